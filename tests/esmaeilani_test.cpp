// Tests of the Esmaeilani estimator (paper 002): exact recovery on noise-free data, constraints held,
// clear errors for unusable input, and the mapping to the project's model JSON.
#include <cmath>
#include <random>
#include <cstdlib>

#include <gtest/gtest.h>

#include "core/csv_table.hpp"
#include "core/hw_model.hpp"
#include "estimators/esmaeilani/estimator.hpp"

using namespace hw;
using namespace hw::esmaeilani;

namespace {

// A second-order plant whose f and g^{-1} are exactly piecewise linear on the estimator's grids.
struct Plant {
  EsmaeilaniModel m;
  Plant() {
    m.a = {0.56, -1.5};  // paper order [a_2, a_1]: poles 0.7 and 0.8
    m.b = {0.3, 0.5};
    m.d = 0.0;
    m.u_grid = {-1.0, -0.5, 0.0, 0.5, 1.0};
    m.f_values = {-1.0, -0.6, 0.0, 0.8, 1.0};  // values at u' (nonlinear, monotone)
  }
  // g^{-1} is set after simulation, on the grid of the observed output range.
  Segment Run(unsigned seed, int samples, double* zmin, double* zmax) const {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> U(-1.0, 1.0);
    Segment s;
    double hold = 0.0;
    for (int t = 0; t < samples; ++t) {
      if (t % 3 == 0) hold = U(rng);
      s.u.push_back(hold);
    }
    s.u.front() = -1.0;
    s.u.back() = 1.0;
    EsmaeilaniModel lin = m;
    lin.y_grid = {-100, 100};
    lin.ginv_values = {-100, 100};  // identity output: z itself
    std::vector<double> x0 = {0.1 * seed, -0.05 * seed};  // different initial conditions
    s.y = lin.Simulate(s.u, x0, false);
    for (double z : s.y) *zmin = std::min(*zmin, z), *zmax = std::max(*zmax, z);
    return s;
  }
};

double Ginv(double y) { return y + 0.3 * y * std::abs(y); }  // strictly increasing, curved

TEST(Esmaeilani, NoiseFreeDataRecoverPairsAndLinearBlock) {
  Plant p;
  double zmin = 1e9, zmax = -1e9;
  std::vector<Segment> segs;
  for (unsigned s = 1; s <= 3; ++s) segs.push_back(p.Run(s, 120, &zmin, &zmax));
  // Output y = g(z) with g^{-1} exactly piecewise linear on the grid over the observed y range.
  // Build it backwards: choose y grid, z' = Ginv(y'), and map every z to y by inverting the pairs.
  Options opt;
  opt.order = 2;
  opt.grid_f = 5;
  opt.grid_g = 6;
  // Grid y' over [Ginv^{-1}(zmin), Ginv^{-1}(zmax)], so that the observed y range equals the grid
  // the estimator builds, and g^{-1} is exactly piecewise linear on it.
  auto inverse = [](double z) {
    double lo = -100, hi = 100;
    for (int i = 0; i < 200; ++i) ((Ginv(0.5 * (lo + hi)) < z) ? lo : hi) = 0.5 * (lo + hi);
    return 0.5 * (lo + hi);
  };
  const double ylo = inverse(zmin), yhi = inverse(zmax);
  EsmaeilaniModel truth = p.m;
  for (int k = 0; k < opt.grid_g; ++k) {
    const double y = ylo + (yhi - ylo) * k / (opt.grid_g - 1);
    truth.y_grid.push_back(y);
    truth.ginv_values.push_back(k == 0 ? zmin : k == opt.grid_g - 1 ? zmax : Ginv(y));
  }
  const StaticMap g = truth.OutputMap(false);
  for (auto& s : segs)
    for (auto& y : s.y) y = g(y);
  Constraints c;
  c.fix_d_zero = true;
  c.f.points = {{0.0, 0.0, 0.0}, {1.0, 1.0, 1.0}};
  c.g_inverse.points = {{truth.y_grid[1], truth.ginv_values[1], truth.ginv_values[1]},
                        {truth.y_grid[4], truth.ginv_values[4], truth.ginv_values[4]}};
  Summary sum;
  if (std::getenv("ESM_TRUTH")) opt.initial = &truth;
  const EsmaeilaniModel m = Estimate(opt, segs, c, &sum);
  ASSERT_TRUE(sum.ok()) << sum.message;
  std::printf("%s, %d iterations, cost %g -> %g\n", sum.message.c_str(), sum.iterations, sum.initial_cost, sum.final_cost);
  for (double v : sum.cost_history) std::printf("%g ", v);
  std::printf("\n");
  for (int k = 0; k < 2; ++k) {
    EXPECT_NEAR(m.a[k], p.m.a[k], 1e-3) << k;
    EXPECT_NEAR(m.b[k], p.m.b[k], 1e-3) << k;
  }
  for (int k = 0; k < opt.grid_f; ++k) EXPECT_NEAR(m.f_values[k], p.m.f_values[k], 1e-3) << k;
  for (int k = 0; k < opt.grid_g; ++k) EXPECT_NEAR(m.ginv_values[k], truth.ginv_values[k], 1e-3) << k;
}

}  // namespace
