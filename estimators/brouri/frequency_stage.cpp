#include "estimators/brouri/frequency_stage.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <fmt/format.h>

#include "core/input_error.hpp"
#include "estimators/brouri/outliers.hpp"

namespace hw::brouri {

namespace {
using cd = std::complex<double>;
constexpr double kPi = std::numbers::pi;

double Binomial(int n, int k) {
  double r = 1.0;
  for (int i = 1; i <= k; ++i) r = r * (n - k + i) / i;
  return r;
}

// P_k as ascending coefficients in g.
std::vector<double> HarmonicPolynomial(const std::vector<double>& c, int k) {
  const int p = static_cast<int>(c.size()) - 1;
  std::vector<double> out(p + 1, 0.0);
  for (int i = k; i <= p; i += 2) out[i] = c[i] * Binomial(i, (i + k) / 2) / std::pow(2.0, i);
  return out;
}

cd Model(const std::vector<std::vector<double>>& pk, int k, double g, double phi) {
  return std::polar(PolyEval(pk[k], g), -k * (phi + kPi / 2));
}

double Wrap(double a) {
  a = std::fmod(a + kPi, 2 * kPi);
  if (a < 0) a += 2 * kPi;
  return a - kPi;
}
}  // namespace

std::vector<double> PeriodicAverage(const std::vector<double>& y, std::size_t first, int samples_per_period,
                                    int periods, std::vector<std::size_t>* outliers) {
  if (samples_per_period < 4 || periods < 1) throw InputError("periodic averaging needs >= 4 samples per period, >= 1 period");
  const std::size_t need = first + static_cast<std::size_t>(samples_per_period) * periods;
  if (y.size() < need)
    throw InputError(fmt::format("recording has {} samples; {} transient samples + {} periods x {} samples need {}",
                                 y.size(), first, periods, samples_per_period, need));
  const std::size_t P = static_cast<std::size_t>(samples_per_period);
  auto at = [&](int l, std::size_t i) { return first + static_cast<std::size_t>(l) * P + i; };
  // In steady state every period repeats: each phase's samples scatter around their median by the noise only.
  std::vector<double> median(P), residuals;
  double top = 0.0;
  for (std::size_t i = 0; i < P; ++i) {
    std::vector<double> v(periods);
    for (int l = 0; l < periods; ++l) v[l] = y[at(l, i)];
    median[i] = Median(v);
    top = std::max(top, std::abs(median[i]));
    for (double x : v) residuals.push_back(x - median[i]);
  }
  const double threshold = periods >= 3 ? std::max(kOutlierSigmas * RobustSigma(residuals), kOutlierFloor * top)
                                        : INFINITY;  // two periods cannot tell which one is wrong
  std::vector<double> x(P, 0.0);
  for (std::size_t i = 0; i < P; ++i) {
    int n = 0;
    for (int l = 0; l < periods; ++l) {
      const double v = y[at(l, i)];
      if (std::abs(v - median[i]) > threshold) {
        if (outliers) outliers->push_back(at(l, i));
        continue;
      }
      x[i] += v;
      ++n;
    }
    x[i] /= n;
  }
  if (outliers) std::sort(outliers->begin(), outliers->end());
  return x;
}

std::vector<Harmonic> FourierCoefficients(const std::vector<double>& x, int max_harmonic) {
  const int n = static_cast<int>(x.size());
  if (2 * max_harmonic >= n)
    throw InputError(fmt::format("{} samples per period resolve harmonics below {}, harmonic {} requested", n,
                                 (n + 1) / 2, max_harmonic));
  std::vector<Harmonic> out(max_harmonic + 1);
  for (int k = 0; k <= max_harmonic; ++k) {
    double a = 0, b = 0;
    for (int i = 0; i < n; ++i) {
      const double th = 2 * kPi * k * i / n;
      a += x[i] * std::cos(th);
      b += x[i] * std::sin(th);
    }
    out[k].a = 2 * a / n;
    out[k].b = k == 0 ? 0.0 : 2 * b / n;
    out[k].s = k == 0 ? out[k].a / 2 : std::hypot(out[k].a, out[k].b);
    out[k].psi = k == 0 ? 0.0 : std::atan2(out[k].a, out[k].b);
  }
  return out;
}

bool FrequencyOptions::IsValid(std::string* error) const {
  if (harmonic < 0 || harmonic > 15) {
    if (error) *error = fmt::format("harmonic {} must be in [1, 15] (0 = degree of h)", harmonic);
    return false;
  }
  return true;
}

void EstimateFrequencyPoint(const FrequencyOptions& options, const std::vector<double>& h, double amplitude,
                            double omega, double sample_time, const std::vector<double>& period,
                            FrequencyPoint* point, Summary* summary) {
  *summary = {};
  *point = {};
  std::string err;
  if (!options.IsValid(&err)) throw InputError(err);
  if (!(amplitude > 0) || !(omega > 0)) throw InputError("sine amplitude and frequency must be positive");
  std::vector<double> c = h;
  while (c.size() > 2 && c.back() == 0.0) c.pop_back();
  const int p = static_cast<int>(c.size()) - 1;
  const int k = options.harmonic == 0 ? p : options.harmonic;
  if (k > p)
    throw InputError(fmt::format("harmonic {} is absent from x(t): h^ has degree {} (choose k <= {})", k, p, p));
  std::vector<std::vector<double>> pk(p + 1);
  for (int i = 0; i <= p; ++i) pk[i] = HarmonicPolynomial(c, i);
  if (std::all_of(pk[k].begin(), pk[k].end(), [](double v) { return v == 0.0; }))
    throw InputError(fmt::format("harmonic {} carries no information: h^ has no power >= {} of its parity", k, k));

  point->omega = omega;
  point->amplitude = amplitude;
  point->sample_time = sample_time;
  point->harmonic = k;
  point->harmonics = FourierCoefficients(period, p);
  std::vector<cd> meas(p + 1);
  double energy = 0.0;
  for (int i = 1; i <= p; ++i) {
    meas[i] = cd(point->harmonics[i].a, -point->harmonics[i].b) / 2.0;
    energy += std::norm(meas[i]);
  }

  // g = U|G| candidates from |P_k(g)| = |C_k|, g > 0.
  std::vector<double> gs;
  for (double sign : {1.0, -1.0}) {
    auto q = pk[k];
    q[0] -= sign * std::abs(meas[k]);
    for (double r : PolyRealRoots(q, 1e-7))
      if (r > 0) gs.push_back(r);
  }
  if (gs.empty())
    throw InputError(fmt::format("omega = {}: harmonic {} amplitude {:.3g} is not reachable by h^ for any gain", omega,
                                 k, 2 * std::abs(meas[k])));
  double best_r = INFINITY, best_g = 0, best_phi = 0;
  for (double g : gs) {
    const double pg = PolyEval(pk[k], g);
    if (pg == 0.0) continue;
    // C_k = j^-k P_k(g) e^{-j k phi}  =>  k phi = -arg(C_k j^k / P_k(g)) mod 2 pi.
    const double base = -std::arg(meas[k] * std::polar(1.0, k * kPi / 2) / pg);
    for (int m = 0; m < k; ++m) {
      const double phi = (base + 2 * kPi * m) / k;
      double r = 0.0;
      for (int i = 1; i <= p; ++i) r += std::norm(meas[i] - Model(pk, i, g, phi));
      if (r < best_r) best_r = r, best_g = g, best_phi = phi;
    }
  }
  double u_eff = amplitude, delay_phase = 0.0;
  if (options.zoh_correction && sample_time > 0) {
    const double half = omega * sample_time / 2;
    u_eff = amplitude * (half == 0 ? 1.0 : std::sin(half) / half);
    delay_phase = half;
  }
  point->gain = best_g / u_eff;
  point->phase = Wrap(best_phi - delay_phase);
  point->fit_residual = energy > 0 ? std::sqrt(best_r / energy) : 0.0;
  summary->ok = true;
  summary->message = fmt::format("omega = {}: |G| = {:.4f}, phi = {:.4f} rad (harmonic {}, relative misfit {:.2g})",
                                 omega, point->gain, point->phase, k, point->fit_residual);
}

void UnwrapPhases(std::vector<FrequencyPoint>* points) {
  for (std::size_t i = 1; i < points->size(); ++i) {
    double& ph = (*points)[i].phase;
    const double prev = (*points)[i - 1].phase;
    ph = prev + Wrap(ph - prev);
  }
}

nlohmann::json ToJson(const FrequencyPoint& p) {
  nlohmann::json h = nlohmann::json::array();
  for (const auto& x : p.harmonics) h.push_back({{"a", x.a}, {"b", x.b}, {"s", x.s}, {"psi", x.psi}});
  return {{"omega", p.omega},       {"amplitude", p.amplitude}, {"sample_time", p.sample_time},
          {"harmonic", p.harmonic}, {"gain", p.gain},           {"phase", p.phase},
          {"fit_residual", p.fit_residual}, {"fourier", h}, {"outliers", p.outliers}};
}

}  // namespace hw::brouri
