#include "diagnose/residual_analysis.hpp"

#include <algorithm>
#include <cmath>
#include <map>

#include <fmt/format.h>

#include "diagnose/signal_stats.hpp"

namespace hw::diagnose {
namespace {

// Reversals with a dead band of 3 % of the signal's range, so that dither or noise does not count:
// a reversal is a move of more than the band back from the extreme reached since the last one.
// Fills the samples since the last reversal and the current direction (+1 rising, -1 falling).
void Reversals(const std::vector<double>& s, std::vector<double>* since, std::vector<double>* direction) {
  const std::size_t n = s.size();
  since->assign(n, static_cast<double>(n));
  direction->assign(n, 0.0);
  if (n == 0) return;
  const auto [lo, hi] = std::minmax_element(s.begin(), s.end());
  const double band = 0.03 * (*hi - *lo);
  int dir = 0;
  double ext = s[0];
  long last = -1;  // before the first reversal: samples since the start
  for (std::size_t t = 0; t < n; ++t) {
    if (dir >= 0 && s[t] > ext) ext = s[t];
    if (dir <= 0 && s[t] < ext) ext = s[t];
    if (dir == 0 && std::abs(s[t] - s[0]) > band) dir = s[t] > s[0] ? 1 : -1, ext = s[t];
    if (dir > 0 && s[t] < ext - band) dir = -1, ext = s[t], last = static_cast<long>(t);
    if (dir < 0 && s[t] > ext + band) dir = 1, ext = s[t], last = static_cast<long>(t);
    (*since)[t] = static_cast<double>(std::min<long>(static_cast<long>(t) - last, static_cast<long>(n)));
    (*direction)[t] = dir;
  }
}

std::string Num(double v) { return fmt::format("{:.4g}", v); }

}  // namespace

double EstimateNoiseStd(const std::vector<double>& e, std::size_t skip) {
  std::vector<double> d;
  for (std::size_t t = skip + 1; t < e.size(); ++t) d.push_back(e[t] - e[t - 1]);
  if (d.empty()) return 0.0;
  const double med = Median(d);
  for (auto& v : d) v = std::abs(v - med);
  return 1.4826 * Median(d) / std::sqrt(2.0);
}

bool WindowOptions::IsValid(std::string* error) const {
  if (length < 0 || length == 1 || !(alpha > 0 && alpha < 1)) {
    if (error) *error = "window length must be 0 (auto) or >= 2, and alpha in (0, 1)";
    return false;
  }
  return true;
}

double WindowOptions::Threshold(std::size_t n) const {
  const int L = Resolve(n);
  const double windows = std::max(1.0, static_cast<double>(n) / L);
  return ChiSquareQuantile(1.0 - alpha / windows, L) / L;
}

int WindowOptions::Resolve(std::size_t n) const {
  if (length > 0) return length;
  return std::clamp(static_cast<int>(n / 200), 8, 40);
}

std::vector<bool> MismatchMask(const std::vector<double>& e, double sigma, std::size_t skip, const WindowOptions& o) {
  const std::size_t n = e.size();
  const int L = o.Resolve(n);
  std::vector<bool> mask(n, false);
  if (n < skip + L || !(sigma > 0)) return mask;
  const double thr = sigma * sigma * o.Threshold(n - skip);
  std::vector<double> cs(n + 1, 0.0);
  for (std::size_t t = 0; t < n; ++t) cs[t + 1] = cs[t] + (t >= skip ? e[t] * e[t] : 0.0);
  for (std::size_t s = skip; s + L <= n; ++s) {
    if ((cs[s + L] - cs[s]) / L > thr)
      for (std::size_t t = s; t < s + L; ++t) mask[t] = true;
  }
  return mask;
}

std::vector<std::pair<std::size_t, std::size_t>> MaskToWindows(const std::vector<bool>& mask) {
  std::vector<std::pair<std::size_t, std::size_t>> w;
  for (std::size_t t = 0; t < mask.size(); ++t) {
    if (!mask[t]) continue;
    std::size_t e = t;
    while (e + 1 < mask.size() && mask[e + 1]) ++e;
    w.emplace_back(t, e);
    t = e;
  }
  return w;
}

std::vector<Condition> OperatingConditions(const std::vector<double>& u, const std::vector<double>& y) {
  const std::size_t n = u.size();
  std::vector<Condition> c;
  auto diff = [&](const std::vector<double>& s) {
    std::vector<double> d(n, 0.0);
    for (std::size_t t = 1; t < n; ++t) d[t] = s[t] - s[t - 1];
    return d;
  };
  auto absv = [](std::vector<double> s) {
    for (auto& v : s) v = std::abs(v);
    return s;
  };
  const auto du = diff(u), dy = diff(y);
  c.push_back({"u", "input level u", u});
  c.push_back({"abs_u", "input magnitude |u|", absv(u)});
  c.push_back({"y", "output level y (model)", y});
  c.push_back({"abs_y", "output magnitude |y| (model)", absv(y)});
  c.push_back({"du", "input rate du = u_t - u_{t-1}", du});
  c.push_back({"abs_du", "input rate magnitude |du|", absv(du)});
  c.push_back({"dy", "output rate dy (model)", dy});
  c.push_back({"abs_dy", "output rate magnitude |dy| (model)", absv(dy)});
  std::vector<double> since_u, dir_u, since_y, dir_y;
  Reversals(u, &since_u, &dir_u);
  Reversals(y, &since_y, &dir_y);
  c.push_back({"since_rev_u", "samples since the last reversal of u", since_u});
  c.push_back({"since_rev_y", "samples since the last reversal of y (model)", since_y});
  c.push_back({"dir_u", "direction of u since its last reversal (+1 rising, -1 falling)", dir_u});
  c.push_back({"dir_y", "direction of y since its last reversal (model)", dir_y});
  return c;
}

nlohmann::json Region::to_json() const {
  nlohmann::json b = nullptr;
  if (bias.found)
    b = {{"description", bias.description}, {"condition", bias.condition},   {"threshold", bias.threshold},
         {"mean_error_above", bias.mean_above}, {"mean_error_below", bias.mean_below}, {"effect_size", bias.effect_size}};
  if (!found) return {{"description", description}, {"condition", nullptr}, {"signed_error", b}};
  return {{"description", description}, {"condition", condition}, {"relation", relation},
          {"threshold", threshold},     {"precision", precision}, {"recall", recall},
          {"error_lift", lift},         {"signed_error", b}};
}

namespace {
void FindBias(const std::vector<Condition>& conditions, const std::vector<double>& e, std::size_t skip,
              const std::string& subject, Region* r) {
  double mean = 0.0, var = 0.0;
  const double nall = static_cast<double>(e.size() - skip);
  for (std::size_t t = skip; t < e.size(); ++t) mean += e[t];
  mean /= nall;
  for (std::size_t t = skip; t < e.size(); ++t) var += (e[t] - mean) * (e[t] - mean);
  const double sd = std::sqrt(var / nall);
  if (!(sd > 0)) return;
  for (const auto& c : conditions) {
    if (c.name.rfind("abs_", 0) == 0) continue;
    std::vector<double> vals(c.values.begin() + skip, c.values.end());
    std::vector<double> ths;
    for (int i = 1; i < 20; ++i) ths.push_back(Quantile(vals, i / 20.0));
    if (c.name == "dir_u" || c.name == "dir_y") ths = {0.0};
    std::sort(ths.begin(), ths.end());
    ths.erase(std::unique(ths.begin(), ths.end()), ths.end());
    for (double th : ths) {
      double s_in = 0.0, s_out = 0.0;
      std::size_t n_in = 0, n_out = 0;
      for (std::size_t t = skip; t < e.size(); ++t)
        (c.values[t] > th ? (s_in += e[t], ++n_in) : (s_out += e[t], ++n_out));
      if (n_in < 0.1 * nall || n_out < 0.1 * nall) continue;
      const double ma = s_in / n_in, mb = s_out / n_out, es = std::abs(ma - mb) / sd;
      if (es > r->bias.effect_size) r->bias = {true, c.name, "", th, ma, mb, es};
    }
  }
  if (!r->bias.found || r->bias.effect_size < 0.5) {
    r->bias = {};
    return;
  }
  const auto& b = r->bias;
  const bool follows_direction = b.condition == "dir_u" || b.condition == "dir_y";
  const std::string sig = b.condition.find('u') != std::string::npos ? "u" : "y";
  if (follows_direction)
    r->bias.description = fmt::format(
        "the {0}'s sign follows the direction of {1}: mean {2:+.4g} after {1} rose, {3:+.4g} after it fell "
        "({4:.2f} {0} standard deviations apart)",
        subject, sig, b.mean_above, b.mean_below, b.effect_size);
  else
    r->bias.description = fmt::format(
        "the mean {} differs across {} = {:.4g}: {:+.4g} above, {:+.4g} below ({:.2f} {} standard deviations apart)",
        subject, b.condition, b.threshold, b.mean_above, b.mean_below, b.effect_size, subject);
}

// Mean square where a rule holds over that where it does not, at most kMaxLift. What an effect block
// changes in the prediction is exactly zero, or decays to round-off (1e-40 and below), away from where
// the block acts: the plain ratio then reads 1e47, a figure of the round-off, not of the data.
constexpr double kMaxLift = 1e6;
double Lift(double ms_in, double ms_out) {
  if (ms_in <= 0.0) return 0.0;
  return ms_in >= kMaxLift * ms_out ? kMaxLift : ms_in / ms_out;
}
std::string LiftText(double lift) {
  return lift >= kMaxLift ? fmt::format("over {:.0f}x", kMaxLift) : fmt::format("{:.1f}x", lift);
}
}  // namespace

Region CharacteriseRegion(const std::vector<Condition>& conditions, const std::vector<bool>& mask,
                          const std::vector<double>& e, std::size_t skip, const std::string& subject) {
  Region best;
  best.description = fmt::format("none: the {} stays within the noise everywhere", subject);
  std::size_t nmask = 0;
  for (std::size_t t = skip; t < mask.size(); ++t) nmask += mask[t];
  if (nmask == 0) return best;
  FindBias(conditions, e, skip, subject, &best);
  // When the mask covers most samples it no longer separates anything: rank rules by how much more
  // of the squared error than of the samples they capture instead.
  const bool informative = nmask < 0.6 * (mask.size() - skip);
  double e_total = 0.0;
  for (std::size_t t = skip; t < e.size(); ++t) e_total += e[t] * e[t];
  const double nall = static_cast<double>(mask.size() - skip);
  double best_score = -1.0;
  for (const auto& c : conditions) {
    std::vector<double> vals(c.values.begin() + std::min(skip, c.values.size()), c.values.end());
    std::vector<double> ths;
    for (int i = 1; i < 40; ++i) ths.push_back(Quantile(vals, i / 40.0));
    std::sort(ths.begin(), ths.end());
    ths.erase(std::unique(ths.begin(), ths.end()), ths.end());
    for (double th : ths) {
      for (int above = 0; above < 2; ++above) {
        std::size_t tp = 0, sel = 0;
        double e_in = 0.0, e_out = 0.0;
        std::size_t n_in = 0, n_out = 0;
        for (std::size_t t = skip; t < mask.size(); ++t) {
          const bool r = above ? c.values[t] > th : c.values[t] <= th;
          if (r) {
            ++sel;
            tp += mask[t];
            e_in += e[t] * e[t];
            ++n_in;
          } else {
            e_out += e[t] * e[t];
            ++n_out;
          }
        }
        if (sel == 0 || n_out == 0) continue;
        const double prec = double(tp) / sel, rec = double(tp) / nmask;
        const double f1 = prec + rec > 0 ? 2 * prec * rec / (prec + rec) : 0.0;
        const double lift = Lift(e_in / n_in, e_out / n_out);
        const double concentration = e_in / std::max(e_total, 1e-300) - n_in / nall;
        const double score = informative ? f1 : concentration;
        if (score > best_score && lift > 1.3 && n_in >= 0.05 * nall) {
          best_score = score;
          best.found = true;
          best.condition = c.name;
          best.relation = above ? "above" : "below";
          best.threshold = th;
          best.precision = prec;
          best.recall = rec;
          best.lift = lift;
        }
      }
    }
  }
  if (!best.found) {
    best.description = "no single operating condition characterises the flagged samples";
    if (best.bias.found) best.description += "; " + best.bias.description;
    return best;
  }
  const bool above = best.relation == "above";
  const std::string th = Num(best.threshold);
  const std::string& n = best.condition;
  std::string d;
  if (n == "since_rev_u" || n == "since_rev_y") {
    const std::string sig = n == "since_rev_u" ? "u" : "y";
    d = above ? fmt::format("more than {} samples after a reversal of {}", th, sig)
              : fmt::format("within {} samples after a reversal of {}", th, sig);
  } else {
    static const std::map<std::string, std::string> label = {
        {"u", "u"},     {"abs_u", "|u|"}, {"y", "y"},         {"abs_y", "|y|"},
        {"du", "du/dt (per sample)"}, {"dir_u", "direction of u"}, {"dir_y", "direction of y"}, {"abs_du", "|du| per sample"}, {"dy", "dy (per sample)"},
        {"abs_dy", "|dy| per sample"}};
    d = fmt::format("{} {} {}", label.count(n) ? label.at(n) : n, above ? "above" : "at or below", th);
  }
  if (informative)
    best.description = fmt::format("{} (covers {:.0f} % of the flagged samples; {:.0f} % of the samples meeting it "
                                   "are flagged; mean-square {} there {} elsewhere)",
                                   d, 100 * best.recall, 100 * best.precision, subject, LiftText(best.lift));
  else
    best.description = fmt::format("{} beyond the noise almost everywhere ({:.0f} % of the samples); it is largest "
                                   "for {} (mean-square {} there {} elsewhere)",
                                   subject, 100.0 * nmask / nall, d, subject, LiftText(best.lift));
  if (best.bias.found) best.description += "; " + best.bias.description;
  return best;
}

double ChiSquareQuantile(double p, int k) {
  // Acklam-free normal quantile via a rational approximation good to 1e-3, enough for a test threshold.
  auto norm_q = [](double q) {
    const double t = std::sqrt(-2.0 * std::log(q < 0.5 ? q : 1 - q));
    const double z = t - (2.515517 + 0.802853 * t + 0.010328 * t * t) /
                             (1 + 1.432788 * t + 0.189269 * t * t + 0.001308 * t * t * t);
    return q < 0.5 ? -z : z;
  };
  const double z = norm_q(p);
  const double h = 2.0 / (9.0 * k);
  return k * std::pow(1 - h + z * std::sqrt(h), 3);
}

nlohmann::json CorrelationTest::to_json() const {
  return {{"statistic", statistic}, {"dof", dof}, {"threshold_99", threshold}, {"passed", passed}};
}

CorrelationTest WhitenessTest(const std::vector<double>& e, std::size_t skip, int M) {
  CorrelationTest r;
  const std::size_t n = e.size() > skip ? e.size() - skip : 0;
  if (n <= static_cast<std::size_t>(M) + 2) return r;
  double mean = 0.0;
  for (std::size_t t = skip; t < e.size(); ++t) mean += e[t];
  mean /= n;
  auto R = [&](int lag) {
    double s = 0.0;
    for (std::size_t t = skip + lag; t < e.size(); ++t) s += (e[t] - mean) * (e[t - lag] - mean);
    return s / n;
  };
  const double r0 = std::max(R(0), 1e-300);
  for (int k = 1; k <= M; ++k) {
    r.rho.push_back(R(k) / r0);
    r.statistic += n * r.rho.back() * r.rho.back();
  }
  r.dof = M;
  r.threshold = ChiSquareQuantile(0.99, M);
  r.passed = r.statistic <= r.threshold;
  return r;
}

CorrelationTest InputCorrelationTest(const std::vector<double>& e, const std::vector<double>& u, std::size_t skip,
                                     int M) {
  CorrelationTest r;
  const std::size_t n = e.size() > skip ? e.size() - skip : 0;
  if (n <= static_cast<std::size_t>(M) + 2) return r;
  double me = 0.0, mu = 0.0;
  for (std::size_t t = skip; t < e.size(); ++t) me += e[t], mu += u[t];
  me /= n;
  mu /= n;
  double see = 0.0, suu = 0.0;
  for (std::size_t t = skip; t < e.size(); ++t) see += (e[t] - me) * (e[t] - me), suu += (u[t] - mu) * (u[t] - mu);
  const double norm = std::sqrt(std::max(see * suu, 1e-300));
  for (int k = 0; k <= M; ++k) {
    double s = 0.0;
    for (std::size_t t = skip + k; t < e.size(); ++t) s += (e[t] - me) * (u[t - k] - mu);
    r.rho.push_back(s / norm);
    r.statistic += n * r.rho.back() * r.rho.back();
  }
  r.dof = M + 1;
  r.threshold = ChiSquareQuantile(0.99, M + 1);
  r.passed = r.statistic <= r.threshold;
  return r;
}

}  // namespace hw::diagnose
