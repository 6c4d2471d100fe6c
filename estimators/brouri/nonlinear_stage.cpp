#include "estimators/brouri/nonlinear_stage.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/Dense>
#include <fmt/format.h>

#include "core/input_error.hpp"
#include "core/json_input.hpp"
#include "estimators/brouri/outliers.hpp"

namespace hw::brouri {

std::vector<HoldAverage> AverageHolds(const std::vector<double>& y, const std::vector<double>& levels,
                                      int hold_samples, int average_samples) {
  if (average_samples < 2 || average_samples > hold_samples)
    throw InputError(fmt::format("averaging length M = {} must be in [2, hold length {}]", average_samples,
                                 hold_samples));
  const std::size_t needed = levels.size() * static_cast<std::size_t>(hold_samples);
  if (y.size() < needed)
    throw InputError(fmt::format("recording has {} samples, the {} holds of {} samples need {}", y.size(),
                                 levels.size(), hold_samples, needed));
  const std::size_t H = static_cast<std::size_t>(hold_samples), M = static_cast<std::size_t>(average_samples);
  // Robust location and spread of each hold's settled part (its last M samples), and the data's scale.
  std::vector<double> median(levels.size()), sigma(levels.size());
  double lo = INFINITY, hi = -INFINITY, top = 0.0;
  for (std::size_t j = 0; j < levels.size(); ++j) {
    const std::vector<double> window(y.begin() + (j + 1) * H - M, y.begin() + (j + 1) * H);
    median[j] = Median(window);
    sigma[j] = RobustSigma(window);
    lo = std::min(lo, median[j]), hi = std::max(hi, median[j]), top = std::max(top, std::abs(median[j]));
  }
  const double floor = kOutlierFloor * (top + hi - lo) + 1e-300;
  std::vector<HoldAverage> out;
  for (std::size_t j = 0; j < levels.size(); ++j) {
    const std::size_t first = j * H, end = first + H, begin = end - M;
    HoldAverage h{levels[j], 0.0, 0.0, 0};
    h.outliers = IsolatedOutliers(y, first, end, median[j], std::max(kOutlierSigmas * sigma[j], floor));
    auto kept = [&](std::size_t i) { return !std::binary_search(h.outliers.begin(), h.outliers.end(), i); };
    // Mean and standard error of the mean over the kept samples of [from, end).
    auto mean_and_error = [&](std::size_t from, double* mean, double* error) {
      double sum = 0.0, n = 0.0;
      for (std::size_t i = from; i < end; ++i)
        if (kept(i)) sum += y[i], n += 1;
      *mean = sum / n;
      double ss = 0.0;
      for (std::size_t i = from; i < end; ++i)
        if (kept(i)) ss += (y[i] - *mean) * (y[i] - *mean);
      *error = std::sqrt(ss / std::max(1.0, n - 1) / n);
      return static_cast<int>(n);
    };
    h.samples = mean_and_error(begin, &h.mean, &h.std_error);
    mean_and_error(first, &h.hold_mean, &h.hold_std_error);
    h.median = median[j];
    out.push_back(h);
  }
  return out;
}

bool NonlinearOptions::IsValid(std::string* error) const {
  auto fail = [&](std::string m) {
    if (error) *error = std::move(m);
    return false;
  };
  if (degree < 0 || degree > 15) return fail(fmt::format("degree p = {} must be in [1, 15] (0 = select)", degree));
  if (max_degree < 1 || max_degree > 15) return fail(fmt::format("max degree {} must be in [1, 15]", max_degree));
  if (!(plateau_sigmas > 0)) return fail("plateau_sigmas must be positive");
  if (!(plateau_abs_tol >= 0)) return fail("plateau_abs_tol must be >= 0");
  return true;
}

const char* ToString(DownBorderMethod m) {
  switch (m) {
    case DownBorderMethod::kPaperCoefficients: return "paper-coefficients";
    case DownBorderMethod::kLeadingAndRoot: return "leading-and-root";
    case DownBorderMethod::kRootAndSlope: return "root-and-slope";
  }
  return "?";
}

DownBorderMethod DownBorderMethodFromString(const std::string& name) {
  for (auto m : {DownBorderMethod::kPaperCoefficients, DownBorderMethod::kLeadingAndRoot, DownBorderMethod::kRootAndSlope})
    if (name == ToString(m)) return m;
  throw InputError(fmt::format("descending-border method '{}' must be paper-coefficients, leading-and-root or "
                               "root-and-slope",
                               name));
}

namespace {

// "hold 7 (U = 0.4): sample 1235 (y = 1e+06) excluded as an isolated outlier ..." for every flagged hold.
std::string OutlierWarnings(const HoldAverage& reset, const std::vector<HoldAverage>& up,
                            const std::vector<HoldAverage>& down) {
  std::string w;
  std::vector<const HoldAverage*> holds = {&reset};
  for (const auto* v : {&up, &down})
    for (const auto& h : *v) holds.push_back(&h);
  for (std::size_t j = 0; j < holds.size(); ++j) {
    const auto& h = *holds[j];
    if (h.outliers.empty()) continue;
    std::string samples;
    for (std::size_t i : h.outliers) samples += fmt::format("{}{}", samples.empty() ? "" : ", ", i + 1);
    w += fmt::format("hold {} (U = {:g}): sample{} {} left out of the averages as isolated outlier{} (more than {:g} "
                     "robust standard deviations from the hold's settled median {:.6g}). ",
                     j, h.level, h.outliers.size() > 1 ? "s" : "", samples, h.outliers.size() > 1 ? "s" : "",
                     kOutlierSigmas, h.median);
  }
  return w;
}

// Number of leading holds whose output equals the reference hold's (the plateau, eqs. 7a/14a). Each
// candidate's whole-hold mean is compared with the pooled reference; accepted holds join the pool.
int PlateauLength(const HoldAverage& ref, const std::vector<HoldAverage>& holds, const NonlinearOptions& o,
                  double scale) {
  const double floor = 1e-6 * scale + 1e-15;
  double wsum = 1.0 / std::pow(std::max(ref.std_error, floor), 2), msum = ref.mean * wsum;
  int n = 0;
  for (const auto& h : holds) {
    const bool whole = h.hold_std_error > 0;
    const double mean = whole ? h.hold_mean : h.mean, se = std::max(whole ? h.hold_std_error : h.std_error, floor);
    const double ref_mean = msum / wsum, ref_se = 1.0 / std::sqrt(wsum);
    const double tol = o.plateau_sigmas * std::hypot(se, ref_se) + o.plateau_abs_tol + floor;
    if (std::abs(mean - ref_mean) > tol) break;
    wsum += 1.0 / (se * se);
    msum += mean / (se * se);
    ++n;
  }
  return n;
}

double FloorSe(double se, double scale) { return std::max(se, 1e-9 * scale + 1e-15); }

// Chi-square acceptance of a degree-p fit: residuals no larger than the averaging noise explains.
bool FitAccepted(const std::vector<double>& u, const std::vector<double>& x, const std::vector<double>& se, int p,
                 double scale) {
  const auto c = PolyFit(u, x, p);
  double chi2 = 0.0;
  for (std::size_t i = 0; i < u.size(); ++i) {
    const double r = (x[i] - PolyEval(c, u[i])) / FloorSe(se[i], scale);
    chi2 += r * r;
  }
  const double dof = static_cast<double>(u.size()) - p - 1;
  return chi2 <= dof + 4.0 * std::sqrt(2.0 * dof);
}

// The real root of q nearest the interval [lo, hi] (h^-1(0) = 0 makes it unique in the working range).
double RootNearInterval(const std::vector<double>& q, double lo, double hi, const std::string& what,
                        std::string* warnings) {
  const auto roots = PolyRealRoots(q, 1e-6);
  if (roots.empty())
    throw InputError(fmt::format("{}: the fitted polynomial has no real root, so h(0) = 0 cannot place the border; "
                                 "use levels that cross the border's zero or a lower degree",
                                 what));
  auto dist = [&](double r) { return r < lo ? lo - r : (r > hi ? r - hi : 0.0); };
  const double mid = 0.5 * (lo + hi);
  double best = roots.front();
  int inside = 0;
  for (double r : roots) {
    if (dist(r) == 0.0) ++inside;
    if (dist(r) < dist(best) || (dist(r) == dist(best) && std::abs(r - mid) < std::abs(best - mid))) best = r;
  }
  if (inside > 1 && warnings)
    *warnings += fmt::format("{}: {} real roots inside the data range [{}, {}]; took {} (h should vanish only at 0). ",
                             what, inside, lo, hi, best);
  if (dist(best) > 0 && warnings)
    *warnings += fmt::format("{}: root {} lies outside the data range [{}, {}] (extrapolated). ", what, best, lo, hi);
  return best;
}

// h (no constant term) by linear least squares for fixed border lines; returns the residual vector.
Eigen::VectorXd JointResidual(const std::vector<double>& ua, const std::vector<double>& xa,
                              const std::vector<double>& ud, const std::vector<double>& xd, int p,
                              const Eigen::Vector3d& theta, Eigen::VectorXd* coeffs) {
  const Eigen::Index n = static_cast<Eigen::Index>(ua.size() + ud.size());
  Eigen::MatrixXd a(n, p);
  Eigen::VectorXd x(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    const bool up = i < static_cast<Eigen::Index>(ua.size());
    const double w = up ? ua[i] - theta(0) : theta(1) * (ud[i - ua.size()] - theta(2));
    double pw = w;
    for (int k = 0; k < p; ++k, pw *= w) a(i, k) = pw;
    x(i) = up ? xa[i] : xd[i - ua.size()];
  }
  const Eigen::VectorXd c = a.colPivHouseholderQr().solve(x);
  if (coeffs) *coeffs = c;
  return x - a * c;
}

void JointRefit(const std::vector<double>& ua, const std::vector<double>& xa, const std::vector<double>& ud,
                const std::vector<double>& xd, int p, OperatorLines* lines, std::vector<double>* h) {
  Eigen::Vector3d theta(lines->root_up, lines->slope_down, lines->root_down);
  Eigen::VectorXd r = JointResidual(ua, xa, ud, xd, p, theta, nullptr);
  double cost = r.squaredNorm(), lambda = 1e-3;
  for (int it = 0; it < 200; ++it) {
    Eigen::MatrixXd jac(r.size(), 3);
    for (int k = 0; k < 3; ++k) {
      const double step = 1e-7 * (1.0 + std::abs(theta(k)));
      Eigen::Vector3d t = theta;
      t(k) += step;
      jac.col(k) = (JointResidual(ua, xa, ud, xd, p, t, nullptr) - r) / step;
    }
    const Eigen::Matrix3d jtj = jac.transpose() * jac;
    const Eigen::Vector3d g = jac.transpose() * r;
    bool improved = false;
    for (int tries = 0; tries < 20 && !improved; ++tries) {
      Eigen::Matrix3d m = jtj;
      m.diagonal() *= 1.0 + lambda;
      const Eigen::Vector3d delta = -m.ldlt().solve(g);
      const Eigen::Vector3d t = theta + delta;
      if (!(t(1) > 0)) {
        lambda *= 10;
        continue;
      }
      const Eigen::VectorXd rn = JointResidual(ua, xa, ud, xd, p, t, nullptr);
      if (rn.squaredNorm() < cost) {
        const double gain = cost - rn.squaredNorm();
        theta = t, r = rn, cost = rn.squaredNorm(), lambda = std::max(lambda / 10, 1e-12), improved = true;
        if (gain < 1e-15 * (1 + cost) && delta.norm() < 1e-12) it = 1 << 20;
      } else {
        lambda *= 10;
      }
    }
    if (!improved) break;
  }
  Eigen::VectorXd c;
  JointResidual(ua, xa, ud, xd, p, theta, &c);
  lines->root_up = theta(0);
  lines->slope_down = theta(1);
  lines->root_down = theta(2);
  h->assign(p + 1, 0.0);
  for (int k = 0; k < p; ++k) (*h)[k + 1] = c(k);
}

}  // namespace

void EstimateNonlinearities(const NonlinearOptions& options, const HoldAverage& reset,
                            const std::vector<HoldAverage>& up, const std::vector<HoldAverage>& down,
                            NonlinearEstimate* est, Summary* summary) {
  *summary = {};
  *est = {};
  std::string err;
  if (!options.IsValid(&err)) throw InputError(err);
  for (std::size_t j = 1; j < up.size(); ++j)
    if (!(up[j].level > up[j - 1].level)) throw InputError("ascending levels must increase strictly");
  for (std::size_t j = 1; j < down.size(); ++j)
    if (!(down[j].level < down[j - 1].level)) throw InputError("descending levels must decrease strictly");
  if (up.empty() || down.empty()) throw InputError("both an ascending and a descending stage are needed");
  if (!up.empty() && !(reset.level < up.front().level))
    throw InputError(fmt::format("reset level {} must lie below the first ascending level {}", reset.level,
                                 up.front().level));
  double scale = std::abs(reset.mean);
  for (const auto* v : {&up, &down})
    for (const auto& h : *v) scale = std::max(scale, std::abs(h.mean));

  est->reset = reset;
  est->up = up;
  est->down = down;
  est->warnings += OutlierWarnings(reset, up, down);
  est->j_a = PlateauLength(reset, up, options, scale);
  est->j_d = PlateauLength(up.back(), down, options, scale);

  std::vector<double> ua, xa, sa, ud, xd;
  for (std::size_t j = est->j_a; j < up.size(); ++j) ua.push_back(up[j].level), xa.push_back(up[j].mean),
                                                     sa.push_back(up[j].std_error);
  for (std::size_t j = est->j_d; j < down.size(); ++j) ud.push_back(down[j].level), xd.push_back(down[j].mean);
  const int na = static_cast<int>(ua.size()), nd = static_cast<int>(ud.size());
  if (na < 2)
    throw InputError(fmt::format("ascending stage: only {} of {} levels lie on the ascending border (j_a = {}); "
                                 "add levels above U = {}",
                                 na, up.size(), est->j_a, up.back().level));

  int p = options.degree;
  if (p == 0) {
    const int top = std::min(options.max_degree, na - 2);
    for (int q = 1; q <= top && p == 0; ++q)
      if (FitAccepted(ua, xa, sa, q, scale)) p = q;
    if (p == 0) {
      p = std::min(options.max_degree, na - 1);
      est->warnings += fmt::format("degree selection: no degree up to {} explains the ascending points within the "
                                   "noise; using p = {} (add levels or raise max_degree). ",
                                   top, p);
    }
  }
  est->degree = p;
  if (na < p + 1)
    throw InputError(fmt::format("ascending stage: degree p = {} needs N - j_a >= p + 1 = {} border levels (eq. 11), "
                                 "got {} (j_a = {}); add levels above U = {}",
                                 p, p + 1, na, est->j_a, up.back().level));
  if (nd < p + 1)
    throw InputError(fmt::format("descending stage: degree p = {} needs {} levels on the descending border, got {} "
                                 "(j_d = {}); add levels below U = {}",
                                 p, p + 1, nd, est->j_d, down.back().level));

  // Ascending border: q_a(u) = h(u - d+), d+ its root, h(u) = q_a(u + d+) (eq. 12).
  est->q_up = PolyFit(ua, xa, p);
  const double d_up = RootNearInterval(est->q_up, ua.front(), ua.back(), "ascending border", &est->warnings);
  est->h = PolyShift(est->q_up, d_up);
  est->h[0] = 0.0;  // exactly, by construction of d+
  const double lead_h = est->h[p];
  if (lead_h == 0.0) throw InputError("estimated h has a zero leading coefficient; lower the degree");

  // Descending border: q_d(u) = h(S^d (u - d-)).
  est->q_down = PolyFit(ud, xd, p);
  const double ratio = est->q_down[p] / lead_h;
  if (!(ratio > 0))
    throw InputError(fmt::format("descending fit's leading coefficient {} and h^'s {} have opposite signs, so "
                                 "S^d = (ratio)^(1/p) is undefined; the descending levels do not lie on one border",
                                 est->q_down[p], lead_h));
  const double s_lead = std::pow(ratio, 1.0 / p);
  // u^(p-1) coefficient of h(S(u - d)): c_p S^p p (-d) + c_{p-1} S^(p-1).
  est->s_down_leading = s_lead;
  est->d_down_coefficient =
      (est->h[p - 1] * std::pow(s_lead, p - 1) - est->q_down[p - 1]) / (p * lead_h * std::pow(s_lead, p));
  est->d_down_root = RootNearInterval(est->q_down, ud.back(), ud.front(), "descending border", &est->warnings);
  // Slopes at the zero crossing: q_d'(d-) = S^d h'(0) and h'(0) = q_a'(d+); both fits have data there.
  std::vector<double> dqd(p), dqa(p);
  for (int i = 1; i <= p; ++i) dqd[i - 1] = i * est->q_down[i], dqa[i - 1] = i * est->q_up[i];
  const double slope_h0 = PolyEval(dqa, d_up);
  est->s_down_slope = slope_h0 != 0.0 ? PolyEval(dqd, est->d_down_root) / slope_h0 : s_lead;
  double s_down = s_lead, d_down = est->d_down_coefficient;
  if (options.down_border == DownBorderMethod::kLeadingAndRoot) d_down = est->d_down_root;
  if (options.down_border == DownBorderMethod::kRootAndSlope) s_down = est->s_down_slope, d_down = est->d_down_root;
  if (!(s_down > 0)) throw InputError(fmt::format("estimated S^d = {} is not positive", s_down));
  est->lines = {1.0, d_up, s_down, d_down};
  est->paper_lines = est->lines;
  if (options.joint_refit) {
    if (na + nd < p + 4)
      throw InputError(fmt::format("joint refit: {} border points cannot determine h (degree {}) and 3 border "
                                   "parameters with any redundancy; need at least {}",
                                   na + nd, p, p + 4));
    JointRefit(ua, xa, ud, xd, p, &est->lines, &est->h);
    est->q_up = PolyShift(est->h, -est->lines.root_up);
    std::vector<double> scaled = est->h;
    for (int i = 0; i <= p; ++i) scaled[i] *= std::pow(est->lines.slope_down, i);
    est->q_down = PolyShift(scaled, -est->lines.root_down);
    est->joint_refit = true;
  }
  // A backlash's ascending border lies right of its descending one; a backlash-inverse's lies left.
  est->kind = est->lines.root_up >= est->lines.root_down ? OperatorKind::kBacklash : OperatorKind::kBacklashInverse;
  if (est->kind == OperatorKind::kBacklashInverse && (est->j_a > 0 || est->j_d > 0))
    est->warnings += fmt::format("line order says backlash-inverse but plateaus were seen (j_a = {}, j_d = {}). ",
                                 est->j_a, est->j_d);
  est->params = ParamsFromLines(est->kind, est->lines);
  summary->ok = true;
  summary->message = fmt::format("{} detected; p = {}, j_a = {}, j_d = {}; d+ = {:.4f}, S^d = {:.4f}, d- = {:.4f}",
                                 ToString(est->kind), p, est->j_a, est->j_d, est->params.offset_up,
                                 est->params.slope_down, est->params.offset_down);
  if (est->joint_refit) summary->message += " (joint refit of both borders)";
  if (!est->warnings.empty()) summary->message += "; warnings: " + est->warnings;
}

namespace {
nlohmann::json HoldJson(const HoldAverage& h) {
  return {{"level", h.level},         {"mean", h.mean},           {"std_error", h.std_error},
          {"samples", h.samples},     {"hold_mean", h.hold_mean}, {"hold_std_error", h.hold_std_error},
          {"median", h.median},       {"outliers", h.outliers}};
}
HoldAverage HoldFromJson(const nlohmann::json& j) {
  CheckKeys(j, {"level", "mean", "std_error", "samples", "hold_mean", "hold_std_error", "median", "outliers"},
            "nonlinear estimate: hold");
  HoldAverage h{j.at("level").get<double>(), j.at("mean").get<double>(), j.at("std_error").get<double>(),
                j.at("samples").get<int>(), j.value("hold_mean", 0.0), j.value("hold_std_error", 0.0)};
  h.median = j.value("median", h.mean);
  h.outliers = j.value("outliers", std::vector<std::size_t>{});
  return h;
}
}  // namespace

nlohmann::json NonlinearEstimate::to_json() const {
  nlohmann::json j;
  j["operator"] = ToString(kind);
  j["degree"] = degree;
  j["j_a"] = j_a;
  j["j_d"] = j_d;
  j["params"] = {{"S_a", params.slope_up}, {"d_plus", params.offset_up}, {"S_d", params.slope_down},
                 {"d_minus", params.offset_down}};
  j["lines"] = {{"slope_up", lines.slope_up}, {"root_up", lines.root_up}, {"slope_down", lines.slope_down},
                {"root_down", lines.root_down}};
  j["descending_readings"] = {
      {"paper_coefficients", {{"S_d", s_down_leading}, {"d_minus", d_down_coefficient}}},
      {"leading_and_root", {{"S_d", s_down_leading}, {"d_minus", d_down_root}}},
      {"root_and_slope", {{"S_d", s_down_slope}, {"d_minus", d_down_root}}}};
  j["h"] = h;
  j["joint_refit"] = joint_refit;
  j["paper_lines"] = {{"slope_up", paper_lines.slope_up}, {"root_up", paper_lines.root_up},
                      {"slope_down", paper_lines.slope_down}, {"root_down", paper_lines.root_down}};
  j["q_up"] = q_up;
  j["q_down"] = q_down;
  j["reset"] = HoldJson(reset);
  j["up"] = nlohmann::json::array();
  for (const auto& h : up) j["up"].push_back(HoldJson(h));
  j["down"] = nlohmann::json::array();
  for (const auto& h : down) j["down"].push_back(HoldJson(h));
  j["warnings"] = warnings;
  return j;
}

NonlinearEstimate NonlinearEstimate::from_json(const nlohmann::json& j,
                                                const std::vector<std::string_view>& extension_keys) {
  try {
    std::vector<std::string_view> keys = {"operator", "degree", "j_a", "j_d", "params", "lines",
                                          "descending_readings", "h", "joint_refit", "paper_lines", "q_up",
                                          "q_down", "reset", "up", "down", "warnings"};
    keys.insert(keys.end(), extension_keys.begin(), extension_keys.end());
    CheckKeys(j, keys, "nonlinear estimate");
    NonlinearEstimate e;
    const auto op = j.at("operator").get<std::string>();
    if (op != "backlash" && op != "backlash-inverse")
      throw InputError(fmt::format("operator '{}' must be 'backlash' or 'backlash-inverse'", op));
    e.kind = op == "backlash" ? OperatorKind::kBacklash : OperatorKind::kBacklashInverse;
    e.degree = j.at("degree").get<int>();
    e.j_a = j.value("j_a", 0);
    e.j_d = j.value("j_d", 0);
    const auto& pj = j.at("params");
    CheckKeys(pj, {"S_a", "d_plus", "S_d", "d_minus"}, "nonlinear estimate: params");
    // Derived records (recomputed from params, not read) must still hold only their own keys.
    for (const char* lines : {"lines", "paper_lines"})
      if (j.contains(lines))
        CheckKeys(j.at(lines), {"slope_up", "root_up", "slope_down", "root_down"}, std::string("nonlinear estimate: ") + lines);
    if (j.contains("descending_readings")) {
      const auto& r = j.at("descending_readings");
      CheckKeys(r, {"paper_coefficients", "leading_and_root", "root_and_slope"}, "nonlinear estimate: descending_readings");
      for (const auto& [name, reading] : r.items())
        CheckKeys(reading, {"S_d", "d_minus"}, "nonlinear estimate: descending_readings: " + name);
    }
    e.params = {pj.at("S_a").get<double>(), pj.at("d_plus").get<double>(), pj.at("S_d").get<double>(),
                pj.at("d_minus").get<double>()};
    e.lines = LinesOf(e.kind, e.params);
    e.h = j.at("h").get<std::vector<double>>();
    e.q_up = j.value("q_up", std::vector<double>{});
    e.q_down = j.value("q_down", std::vector<double>{});
    if (j.contains("reset")) e.reset = HoldFromJson(j.at("reset"));
    for (const auto& h : j.value("up", nlohmann::json::array())) e.up.push_back(HoldFromJson(h));
    for (const auto& h : j.value("down", nlohmann::json::array())) e.down.push_back(HoldFromJson(h));
    e.warnings = j.value("warnings", std::string());
    std::string err;
    if (!e.params.IsValid(&err)) throw InputError("nonlinear estimate: " + err);
    if (e.h.size() < 2 || static_cast<int>(e.h.size()) != e.degree + 1)
      throw InputError(fmt::format("nonlinear estimate: h has {} coefficients, degree {} needs {}", e.h.size(),
                                   e.degree, e.degree + 1));
    return e;
  } catch (const nlohmann::json::exception& ex) {
    throw InputError(std::string("nonlinear estimate JSON: ") + ex.what());
  }
}

MemoryOperator NonlinearEstimate::Precompensator() const {
  // The input must sit on the "up" line v = s (u - r) while z rises and on the "down" line while it
  // falls: u = z / s + r, switching lines at each reversal. That is an operator of the eq. 2 (jump) form
  // for BOTH kinds. For a backlash it is the backlash-inverse of Lemma 1 and the cascade is exact. For a
  // backlash-inverse plant, the jump at a reversal goes the "wrong" way (u rises while z starts falling),
  // so the plant follows its up line for that one sample: a glitch that lasts zero time in continuous
  // time and one sample here. (Lemma 1's second claim, B_inv o B = I, does not hold inside the gap.)
  const OperatorLines l = LinesOf(kind, params);
  return MemoryOperator(OperatorKind::kBacklashInverse, {l.slope_up, l.root_up, l.slope_down, l.root_down});
}

}  // namespace hw::brouri
