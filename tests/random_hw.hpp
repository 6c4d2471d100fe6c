#pragma once
// Seeded random Hammerstein-Wiener systems for tests: several structures (na, nb in 1..3, proper and strictly
// proper, input bases poly:1..3 or "w,tanh", output bases poly:1..3), a stable linear block, an output map
// increasing on the whole range of the noise bands, a uniform or multisine input and uniform noise within a
// given bound. Every draw is a function of the seed alone.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "dss/basis.hpp"
#include "dss/hw_outer_set.hpp"

namespace hw::testing {

struct RandomHwOptions {
  int min_samples = 100, max_samples = 300;
  double noise_bound = 0.05;  // |eta_t| <= noise_bound, in units of w (whose peak is output_peak)
  double output_peak = 2.0;   // max |w_t| (less when the output map increases only on a shorter range)
};

struct RandomHwInstance {
  dss::HwStructure structure;
  dss::HwData data;
  std::vector<double> theta;  // the truth in the layout's order [gamma_2.., alpha_2.., a_1..a_na, b_j0..b_nb]
  std::vector<double> w;      // the noise-free output
  std::string description;    // structure and seed, for failure messages
};

// A small deterministic generator (the standard distributions' results differ between libraries).
class TestRng {
 public:
  explicit TestRng(uint64_t seed) : state_(seed * 0x9E3779B97F4A7C15ull + 0x2545F4914F6CDD1Dull) {}
  uint64_t next() {
    state_ ^= state_ >> 12, state_ ^= state_ << 25, state_ ^= state_ >> 27;
    return state_ * 0x2545F4914F6CDD1Dull;
  }
  double uniform(double lo, double hi) { return lo + (hi - lo) * static_cast<double>(next() >> 11) * 0x1.0p-53; }
  int integer(int lo, int hi) { return lo + static_cast<int>(next() % static_cast<uint64_t>(hi - lo + 1)); }
  double signed_magnitude(double lo, double hi) { return (next() & 1 ? 1.0 : -1.0) * uniform(lo, hi); }

 private:
  uint64_t state_;
};

namespace random_hw_detail {

// a_1..a_na of prod (q - p_i) for stable poles (a complex pair with probability 1/2 when na >= 2).
inline std::vector<double> StableDenominator(int na, TestRng& rng) {
  std::vector<double> c = {1.0};  // coefficients of q^na, q^(na-1), ...
  auto multiply = [&c](const std::vector<double>& f) {
    std::vector<double> r(c.size() + f.size() - 1, 0.0);
    for (std::size_t i = 0; i < c.size(); ++i)
      for (std::size_t j = 0; j < f.size(); ++j) r[i + j] += c[i] * f[j];
    c = r;
  };
  int left = na;
  if (na >= 2 && rng.next() % 2) {
    const double r = rng.uniform(0.3, 0.9), angle = rng.uniform(0.2, 2.9);
    multiply({1.0, -2.0 * r * std::cos(angle), r * r});
    left -= 2;
  }
  for (; left > 0; --left) multiply({1.0, -rng.uniform(-0.9, 0.9)});
  return {c.begin() + 1, c.end()};
}

inline std::vector<double> Input(int n, TestRng& rng) {
  const double peak = rng.uniform(0.5, 2.0);
  std::vector<double> u(n);
  if (rng.next() % 2) {
    for (double& v : u) v = rng.uniform(-peak, peak);
    return u;
  }
  const int tones = rng.integer(2, 6);
  std::vector<double> f(tones), phase(tones);
  for (int k = 0; k < tones; ++k) f[k] = rng.uniform(0.01, 0.49), phase[k] = rng.uniform(0.0, 2 * std::numbers::pi);
  double max_abs = 0.0;
  for (int t = 0; t < n; ++t) {
    u[t] = 0.0;
    for (int k = 0; k < tones; ++k) u[t] += std::sin(2 * std::numbers::pi * f[k] * t + phase[k]);
    max_abs = std::max(max_abs, std::abs(u[t]));
  }
  for (double& v : u) v *= peak / max_abs;
  return u;
}

inline double OutputMap(const dss::HwStructure& s, const std::vector<double>& alpha, double w) {
  double p = 0.0;
  for (std::size_t j = 0; j < alpha.size(); ++j) p += alpha[j] * s.output_basis[j].value(w);
  return p;
}

// The largest W <= 4 with p' >= 0.2 on [-W, W] (p(w) = w + ..., so p'(0) = 1), by a scan from 0 outward.
inline double IncreasingHalfRange(const dss::HwStructure& s, const std::vector<double>& alpha) {
  const double h = 1e-3;
  for (double W = h; W <= 4.0; W += h) {
    for (double w : {W, -W})
      if ((OutputMap(s, alpha, w + 0.5 * h) - OutputMap(s, alpha, w - 0.5 * h)) / h < 0.2) return W - h;
  }
  return 4.0;
}

// w with p(w) = z on [lo, hi], where p increases.
inline double InvertOutputMap(const dss::HwStructure& s, const std::vector<double>& alpha, double z, double lo,
                              double hi) {
  for (int it = 0; it < 200 && hi - lo > 1e-15 * (1 + std::abs(lo)); ++it) {
    const double mid = 0.5 * (lo + hi);
    (OutputMap(s, alpha, mid) < z ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

}  // namespace random_hw_detail

inline RandomHwInstance MakeRandomHwInstance(uint64_t seed, const RandomHwOptions& options = {}) {
  using namespace random_hw_detail;
  TestRng rng(seed);
  RandomHwInstance inst;
  auto& s = inst.structure;
  s.na = rng.integer(1, 3);
  s.nb = rng.integer(1, 3);
  s.strictly_proper = rng.next() % 2;
  const std::vector<std::string> input_bases = {"poly:1", "poly:2", "poly:3", "w,tanh"};
  const std::string input_name = input_bases[rng.integer(0, 3)];
  const std::string output_name = fmt::format("poly:{}", rng.integer(1, 3));
  s.input_basis = dss::parse_basis(input_name);
  s.output_basis = dss::parse_basis(output_name);
  const int j0 = s.strictly_proper ? 1 : 0;
  const int n = rng.integer(options.min_samples, options.max_samples);
  inst.description = fmt::format("seed {}: na {} nb {} {} input {} output {} N {}", seed, s.na, s.nb,
                                 s.strictly_proper ? "strictly proper" : "proper", input_name, output_name, n);

  std::vector<double> gamma = {1.0}, alpha = {1.0};
  for (std::size_t k = 1; k < s.input_basis.size(); ++k) gamma.push_back(rng.uniform(-0.5, 0.5));
  if (alpha.size() < s.output_basis.size()) alpha.push_back(rng.signed_magnitude(0.05, 0.5));
  if (alpha.size() < s.output_basis.size()) alpha.push_back(rng.uniform(0.3, 1.5));  // w^3 keeps p increasing far out
  const std::vector<double> a = StableDenominator(s.na, rng);
  std::vector<double> b;
  for (int j = j0; j <= s.nb; ++j) b.push_back(rng.signed_magnitude(0.3, 2.0));

  // Simulate the linear block from a zero state 50 samples before the record, so its initial state is not zero.
  const int burn_in = 50, total = n + burn_in;
  const std::vector<double> u = Input(total, rng);
  std::vector<double> x(total, 0.0), z(total, 0.0);
  for (int t = 0; t < total; ++t) {
    for (std::size_t k = 0; k < gamma.size(); ++k) x[t] += gamma[k] * s.input_basis[k].value(u[t]);
    for (int i = 1; i <= s.na && i <= t; ++i) z[t] -= a[i - 1] * z[t - i];
    for (int j = j0; j <= s.nb && j <= t; ++j) z[t] += b[j - j0] * x[t - j];
  }
  // Scale b (and so z) so that w = p^-1(z) peaks at the smaller of output_peak and 70 % of the range where p
  // increases; the rest of that range holds the noise bands.
  const double W = IncreasingHalfRange(s, alpha);
  const double w_peak = std::min(options.output_peak, 0.7 * W);
  if (options.noise_bound <= 0 || 2 * options.noise_bound >= W - w_peak)
    throw std::invalid_argument(fmt::format("{}: noise bound {} too large for the output map's increasing range",
                                            inst.description, options.noise_bound));
  double z_max = 0.0, z_min = 0.0;
  for (int t = burn_in; t < total; ++t) z_max = std::max(z_max, z[t]), z_min = std::min(z_min, z[t]);
  double scale = std::numeric_limits<double>::infinity();
  if (z_max > 0) scale = std::min(scale, OutputMap(s, alpha, w_peak) / z_max);
  if (z_min < 0) scale = std::min(scale, OutputMap(s, alpha, -w_peak) / z_min);
  if (!std::isfinite(scale)) throw std::logic_error(inst.description + ": the linear block's output is zero");
  for (double& v : b) v *= scale;
  for (double& v : z) v *= scale;

  inst.data.source = fmt::format("random HW system {}", seed);
  for (int t = burn_in; t < total; ++t) {
    const double w = InvertOutputMap(s, alpha, z[t], -W, W);
    inst.w.push_back(w);
    inst.data.u.push_back(u[t]);
    inst.data.y.push_back(w + rng.uniform(-options.noise_bound, options.noise_bound));
    inst.data.noise_bound.push_back(options.noise_bound);
  }
  inst.theta.insert(inst.theta.end(), gamma.begin() + 1, gamma.end());
  inst.theta.insert(inst.theta.end(), alpha.begin() + 1, alpha.end());
  inst.theta.insert(inst.theta.end(), a.begin(), a.end());
  inst.theta.insert(inst.theta.end(), b.begin(), b.end());
  return inst;
}

}  // namespace hw::testing
