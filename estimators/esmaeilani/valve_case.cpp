#include "estimators/esmaeilani/valve_case.hpp"

#include <algorithm>
#include <cmath>
#include <random>

namespace hw::esmaeilani {

double ValveCase::f(double u) const { return std::min(u, dead_band_start); }
double ValveCase::g(double z) const { return std::clamp((z - g_offset) / g_gain, 0.0, 100.0); }
double ValveCase::g_inverse(double y) const { return g_offset + g_gain * y; }

EsmaeilaniModel ValveCase::TrueModel(int grid) const {
  EsmaeilaniModel m;
  m.a = a;
  m.b = b;
  m.d = d;
  m.has_output_range = true;
  m.output_lower = 0.0;
  m.output_upper = 100.0;
  // f exactly as ordered pairs (kink at the dead-band start); g^{-1} on the unsaturated range,
  // with OutputMap's clamping giving the hard saturation.
  m.u_grid = {0.0, dead_band_start, 100.0};
  m.f_values = {0.0, dead_band_start, dead_band_start};
  for (int k = 0; k < grid; ++k) {
    const double y = 100.0 * k / (grid - 1);
    m.y_grid.push_back(y);
    m.ginv_values.push_back(g_inverse(y));
  }
  return m;
}

Segment ValveCase::ClosingOperation(unsigned seed, int samples, std::vector<double>* w) const {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  std::normal_distribution<double> N(0.0, 1.0);
  const int hold = 5 + static_cast<int>(10 * U(rng));
  const double level1 = 40 + 40 * U(rng), level2 = 2 + 28 * U(rng);  // closing ends nearly closed
  const int switch_at = hold + samples / 3 + static_cast<int>(samples / 4 * U(rng));
  const double tau1 = 3 + 8 * U(rng), tau2 = 3 + 8 * U(rng);
  std::vector<double> cmd(samples);
  double c = 100.0, wander = 0.0;
  for (int t = 0; t < samples; ++t) {
    if (t >= hold) {
      const double target = t < switch_at ? level1 : level2;
      const double tau = t < switch_at ? tau1 : tau2;
      c += (target - c) / tau;
      wander = 0.9 * wander + 0.8 * N(rng);  // the PID output is not flat
    }
    cmd[t] = std::clamp(c + (t >= hold ? wander : 0.0), 0.0, 100.0);
  }
  // True plant in observable canonical form, from the fully open steady state.
  EsmaeilaniModel truth = TrueModel(3);
  const auto x0 = truth.SteadyState(cmd[0]);
  const int n = static_cast<int>(a.size());
  std::vector<double> x = x0, next(n);
  Segment seg;
  seg.name = "closing_" + std::to_string(seed);
  if (w) w->assign(samples, 0.0);
  for (int t = 0; t < samples; ++t) {
    const double in = f(cmd[t]);
    const double wt = g(x[n - 1] + d * in);
    if (w) (*w)[t] = wt;
    seg.u.push_back(std::clamp(cmd[t] + input_noise_std * N(rng), 0.0, 100.0));
    seg.y.push_back(wt + output_noise_std * N(rng));
    for (int i = 0; i < n; ++i) next[i] = (i > 0 ? x[i - 1] : 0.0) - a[i] * x[n - 1] + b[i] * in;
    x.swap(next);
  }
  return seg;
}

Constraints ValveCase::KnownInformation() const {
  Constraints c;
  c.fix_d_zero = true;
  c.has_output_range = true;  // valve travel: 0 % (closed) .. 100 % (fully open)
  c.output_lower = 0.0;
  c.output_upper = 100.0;
  c.f.has_range = true;
  c.f.range_lower = 0.0;
  c.f.range_upper = 100.0;
  c.f.slopes.push_back({-1e20, 1e20, 0.0, 5.0});
  c.f.points.push_back({0.0, 0.0, 0.0});
  c.f.points.push_back({50.0, 50.0, 50.0});
  c.g_inverse.points.push_back({20.0, 20.0, 20.0});  // normalisation of g^{-1} (any two points do, see docs)
  c.g_inverse.points.push_back({80.0, 80.0, 80.0});
  c.g_inverse.slopes.push_back({5.0, 95.0, 0.0, 5.0});   // paper: slopes limited on 5 %..95 %
  c.g_inverse.slopes.push_back({-1e20, 1e20, 0.0, 1e20});  // g^{-1} nondecreasing everywhere
  return c;
}

}  // namespace hw::esmaeilani
