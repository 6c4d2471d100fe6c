#include "core/cerone_example.hpp"

#include <cmath>
#include <random>

namespace hw {

double CeroneOutputMap(double z) {
  // Newton on a strictly increasing cubic (derivative 1 + 1.6 w + 9.6 w^2 > 0), safeguarded by bisection.
  double lo = -1.0, hi = 1.0;
  auto f = [z](double w) { return w + 0.8 * w * w + 3.2 * w * w * w - z; };
  while (f(lo) > 0) lo *= 2;
  while (f(hi) < 0) hi *= 2;
  double w = 0.5 * (lo + hi);
  for (int it = 0; it < 200; ++it) {
    const double fw = f(w);
    if (fw > 0) hi = w; else lo = w;
    const double step = fw / (1 + 1.6 * w + 9.6 * w * w);
    double next = w - step;
    if (next <= lo || next >= hi) next = 0.5 * (lo + hi);
    if (std::abs(next - w) <= 1e-15 * std::max(1.0, std::abs(w))) return next;
    w = next;
  }
  return w;
}

CeroneExample SimulateCeroneExample(uint64_t seed, int samples, double snr_db) {
  CeroneExample ex;
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> input(-10.0, 10.0), unit(-1.0, 1.0);
  ex.u.resize(samples);
  for (auto& v : ex.u) v = input(rng);
  std::vector<double> x(samples), z(samples, 0.0);
  for (int t = 0; t < samples; ++t) x[t] = ex.u[t] + 0.4 * ex.u[t] * ex.u[t] - 0.1 * std::pow(ex.u[t], 3);
  for (int t = 0; t < samples; ++t) {
    double acc = 0.0;
    if (t >= 1) acc += -1.8 * z[t - 1] + 1.6 * x[t - 1];
    if (t >= 2) acc += -0.9 * z[t - 2] + 2.1 * x[t - 2];
    z[t] = acc;
  }
  ex.w.resize(samples);
  double pw = 0.0;
  for (int t = 0; t < samples; ++t) {
    ex.w[t] = CeroneOutputMap(z[t]);
    pw += ex.w[t] * ex.w[t];
  }
  ex.noise_bound = std::sqrt(3.0 * (pw / samples) / std::pow(10.0, snr_db / 10.0));
  ex.y.resize(samples);
  double pe = 0.0;
  for (int t = 0; t < samples; ++t) {
    const double eta = ex.noise_bound * unit(rng);
    ex.y[t] = ex.w[t] + eta;
    pe += eta * eta;
  }
  ex.snr_db = 10.0 * std::log10(pw / pe);
  return ex;
}

}  // namespace hw
