// Tests of the Esmaeilani estimator (paper 002): exact recovery on noise-free data, constraints held,
// clear errors for unusable input, and the mapping to the project's model JSON.
#include <cmath>
#include <iostream>
#include <random>
#include <cstdlib>

#include <gtest/gtest.h>

#include "core/hw_model.hpp"
#include "core/input_error.hpp"
#include "estimators/esmaeilani/estimator.hpp"
#include "estimators/esmaeilani/valve_case.hpp"

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
  const EsmaeilaniModel m = Estimate(opt, segs, c, &sum);
  ASSERT_TRUE(sum.ok()) << sum.message;
  for (int k = 0; k < 2; ++k) {
    EXPECT_NEAR(m.a[k], p.m.a[k], 1e-3) << k;
    EXPECT_NEAR(m.b[k], p.m.b[k], 1e-3) << k;
  }
  for (int k = 0; k < opt.grid_f; ++k) EXPECT_NEAR(m.f_values[k], p.m.f_values[k], 1e-3) << k;
  for (int k = 0; k < opt.grid_g; ++k) EXPECT_NEAR(m.ginv_values[k], truth.ginv_values[k], 1e-3) << k;
  EXPECT_NEAR(m.output_offset, 0.0, 1e-4);
  // The project model (transfer-function form, zero initial state) reproduces the state-space simulation.
  const HwModel hm = HwModel::from_json(m.ToHwModel(false).to_json());
  const auto y_tf = hm.simulate(segs[1].u);
  const auto y_ss = m.Simulate(segs[1].u, std::vector<double>(2, 0.0), false);
  for (std::size_t t = 0; t < y_tf.size(); ++t) ASSERT_NEAR(y_tf[t], y_ss[t], 1e-9) << t;
}

// Small noisy problem shared by the constraint and error tests.
std::vector<Segment> NoisyData(int segments, int samples) {
  Plant p;
  double zmin = 1e9, zmax = -1e9;
  std::vector<Segment> segs;
  std::mt19937 rng(7);
  std::normal_distribution<double> N(0.0, 0.02);
  for (int s = 1; s <= segments; ++s) {
    segs.push_back(p.Run(s, samples, &zmin, &zmax));
    for (auto& y : segs.back().y) y = std::tanh(y) + N(rng);
  }
  return segs;
}

Constraints Normalisation() {
  Constraints c;
  c.fix_d_zero = true;
  c.f.points = {{0.0, 0.0, 0.0}, {1.0, 1.0, 1.0}};
  c.g_inverse.points = {{-0.2, -0.2, -0.2}, {0.2, 0.2, 0.2}};
  return c;
}

TEST(Esmaeilani, SolutionRespectsConstraints) {
  auto segs = NoisyData(2, 80);
  Constraints c = Normalisation();
  c.f.has_range = true;
  c.f.range_lower = -0.7;  // tighter than the true f (which reaches -1): must become active
  c.f.range_upper = 1.0;
  c.f.slopes = {{0.0, 1.0, 0.0, 1.2}};  // f slope <= 1.2 on [0, 1] although the truth has 1.6 on [0, 0.5]
  c.g_inverse.slopes = {{-1e20, 1e20, 0.1, 10.0}};
  Options opt;
  opt.order = 2;
  opt.grid_f = 5;
  opt.grid_g = 6;
  opt.max_iterations = 15;
  Summary sum;
  const EsmaeilaniModel m = Estimate(opt, segs, c, &sum);
  ASSERT_TRUE(sum.ok()) << sum.message;
  const double tol = 1e-6;
  bool range_active = false;
  for (int k = 0; k < opt.grid_f; ++k) {
    EXPECT_GE(m.f_values[k], -0.7 - tol);
    EXPECT_LE(m.f_values[k], 1.0 + tol);
    range_active |= m.f_values[k] < -0.7 + 1e-3;
  }
  EXPECT_TRUE(range_active) << "the range constraint should bind";
  for (int k = 0; k + 1 < opt.grid_f; ++k)
    if (m.u_grid[k] >= 0.0)
      EXPECT_LE((m.f_values[k + 1] - m.f_values[k]) / (m.u_grid[k + 1] - m.u_grid[k]), 1.2 + tol);
  for (int k = 0; k + 1 < opt.grid_g; ++k) {
    const double s = (m.ginv_values[k + 1] - m.ginv_values[k]) / (m.y_grid[k + 1] - m.y_grid[k]);
    EXPECT_GE(s, 0.1 - tol);
    EXPECT_LE(s, 10.0 + tol);
  }
  EXPECT_NEAR(m.F(0.0), 0.0, tol);
  EXPECT_NEAR(m.F(1.0), 1.0, tol);
  EXPECT_NEAR(m.Ginv(0.2), 0.2, tol);
  EXPECT_EQ(m.d, 0.0);
}

TEST(Esmaeilani, TooFewDataIsAClearError) {
  auto segs = NoisyData(1, 12);
  Options opt;
  opt.order = 2;
  try {
    Estimate(opt, segs, Normalisation(), nullptr);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("too few data"), std::string::npos) << e.what();
  }
  segs[0].u.resize(3);
  segs[0].y.resize(3);
  EXPECT_THROW(Estimate(opt, segs, Normalisation(), nullptr), InputError);
}

TEST(Esmaeilani, ContradictoryConstraintsAreAClearError) {
  auto segs = NoisyData(2, 80);
  Options opt;
  opt.order = 2;
  opt.grid_f = 5;
  opt.grid_g = 6;
  Constraints c = Normalisation();
  c.f.slopes = {{-1e20, 1e20, -1e20, -0.1}};  // decreasing, yet f(0) = 0 < f(1) = 1
  try {
    Estimate(opt, segs, c, nullptr);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("contradict"), std::string::npos) << e.what();
  }
  // Directly contradictory range and point: caught before solving.
  Constraints d = Normalisation();
  d.f.has_range = true;
  d.f.range_lower = 2.0;
  d.f.range_upper = 3.0;
  EXPECT_THROW(Estimate(opt, segs, d, nullptr), InputError);
  // No normalisation of g^{-1}: the trivial solution exists, refuse with an explanation.
  Constraints e = Normalisation();
  e.g_inverse.points.clear();
  EXPECT_THROW(Estimate(opt, segs, e, nullptr), InputError);
}

TEST(Esmaeilani, ConstraintsJsonErrorsNameTheProblem) {
  EXPECT_THROW(Constraints::FromJson(nlohmann::json::parse(R"({"f": {"rnage": [0, 1]}})"), "c.json"), InputError);
  EXPECT_THROW(Constraints::FromJson(nlohmann::json::parse(R"({"f": {"points": [[1]]}})"), "c.json"), InputError);
  const auto c = Constraints::FromJson(
      nlohmann::json::parse(R"({"f": {"range": [0, 100], "slopes": [{"min": 0, "max": 5}], "points": [[0, 0], [50, 45, 55]]},
                                 "g_inverse": {"points": [[20, 20], [80, 80]]}, "d": 0})"), "c.json");
  EXPECT_TRUE(c.fix_d_zero);
  EXPECT_EQ(c.f.points.size(), 2u);
  EXPECT_EQ(c.f.points[1].upper, 55.0);
}

TEST(Esmaeilani, PaperValveBlockMapsToProjectConvention) {
  // Paper Section 4.2: a = [-0.0009 0.7650 -1.7484], b = [0.7959 -1.7600 0.9884], d = 0.
  EsmaeilaniModel m;
  m.a = {-0.0009, 0.7650, -1.7484};
  m.b = {0.7959, -1.7600, 0.9884};
  m.u_grid = {0, 100};
  m.f_values = {0, 100};
  m.y_grid = {-1000, 1000};
  m.ginv_values = {-1000, 1000};
  const HwModel h = m.ToHwModel(false);
  EXPECT_EQ(h.linear.delay, 1);
  EXPECT_EQ(h.linear.a, (std::vector<double>{-1.7484, 0.7650, -0.0009}));
  EXPECT_EQ(h.linear.b, (std::vector<double>{0.9884, -1.7600, 0.7959}));
  std::vector<double> u(60, 0.0);
  u[0] = 1.0;
  const auto a = h.simulate(u);
  const auto b = m.Simulate(u, std::vector<double>(3, 0.0), false);
  for (std::size_t t = 0; t < u.size(); ++t) EXPECT_NEAR(a[t], b[t], 1e-9);
  // With feedthrough d the project form has delay 0 and b_k = B_{n-k+1} + d a_k.
  m.d = 0.5;
  const HwModel hd = m.ToHwModel(false);
  EXPECT_EQ(hd.linear.delay, 0);
  EXPECT_NEAR(hd.linear.b[0], 0.5, 1e-15);
  EXPECT_NEAR(hd.linear.b[1], 0.9884 + 0.5 * -1.7484, 1e-12);
  const auto c = hd.simulate(u);
  const auto d = m.Simulate(u, std::vector<double>(3, 0.0), false);
  for (std::size_t t = 0; t < u.size(); ++t) EXPECT_NEAR(c[t], d[t], 1e-9);
}


TEST(Esmaeilani, KnownOutputRangeSaturatesOnlyAtTheLimits) {
  // g^{-1}(y) = 2 y on y in [20, 80] (the identified pairs): g(z) = z / 2 on z in [40, 160].
  EsmaeilaniModel m;
  m.y_grid = {20, 50, 80};
  m.ginv_values = {40, 100, 160};
  const StaticMap held = m.OutputMap(true);  // no known range: held beyond the identified pairs
  EXPECT_NEAR(held(20.0), 20.0, 1e-12);
  EXPECT_NEAR(held(190.0), 80.0, 1e-12);
  m.has_output_range = true;
  m.output_lower = 0.0;
  m.output_upper = 100.0;
  const StaticMap g = m.OutputMap(true);  // linear up to the known limits, then saturated
  EXPECT_NEAR(g(20.0), 10.0, 1e-12);
  EXPECT_NEAR(g(190.0), 95.0, 1e-12);
  EXPECT_NEAR(g(200.0), 100.0, 1e-12);
  EXPECT_NEAR(g(260.0), 100.0, 1e-12);
  EXPECT_NEAR(g(-5.0), 0.0, 1e-12);
  const auto c = Constraints::FromJson(nlohmann::json::parse(R"({"output_range": [0, 100], "saturation_tolerance": 1})"),
                                       "c.json");
  EXPECT_TRUE(c.has_output_range);
  EXPECT_EQ(c.output_upper, 100.0);
  EXPECT_EQ(c.saturation_tolerance, 1.0);
  EXPECT_THROW(Constraints::FromJson(nlohmann::json::parse(R"({"output_range": [100, 0]})"), "c.json"), InputError);
  EXPECT_THROW(Constraints::FromJson(nlohmann::json::parse(R"({"saturation_tolerance": 1})"), "c.json"), InputError);
}

TEST(Esmaeilani, SaturationHandlingNeedsItsAssumptions) {
  auto segs = NoisyData(2, 80);
  Options opt;
  opt.order = 2;
  opt.grid_f = 5;
  opt.grid_g = 6;
  Constraints c = Normalisation();
  c.has_output_range = true;
  c.output_lower = -10.0;
  c.output_upper = 10.0;
  c.saturation_tolerance = 0.1;
  c.fix_d_zero = false;  // censoring with feedthrough is refused
  EXPECT_THROW(Estimate(opt, segs, c, nullptr), InputError);
  c.fix_d_zero = true;  // ... and without a known direction of g^{-1}
  EXPECT_THROW(Estimate(opt, segs, c, nullptr), InputError);
  c.g_inverse.slopes = {{-1e20, 1e20, 0.0, 1e20}};
  Summary sum;
  Estimate(opt, segs, c, &sum);
  EXPECT_EQ(sum.censored_samples, 0);  // no sample near +-10
  EXPECT_TRUE(sum.ok()) << sum.message;
}

TEST(Esmaeilani, IpoptAndCgalSolveTheSameQp) {
  // min 1/2 x^T H x + c^T x with H = [[2, 1], [1, 4]], c = [-1, -6], s.t. x0 + x1 <= 1, x0 >= 0.2.
  SparseQp qp;
  qp.H.resize(2, 2);
  qp.H.insert(0, 0) = 2.0;
  qp.H.insert(1, 0) = 1.0;
  qp.H.insert(0, 1) = 1.0;
  qp.H.insert(1, 1) = 4.0;
  qp.c = Eigen::Vector2d(-1.0, -6.0);
  qp.A.resize(1, 2);
  qp.A.insert(0, 0) = 1.0;
  qp.A.insert(0, 1) = 1.0;
  qp.row_lower = Eigen::VectorXd::Constant(1, -1e20);
  qp.row_upper = Eigen::VectorXd::Constant(1, 1.0);
  qp.var_lower = Eigen::Vector2d(0.2, -1e20);
  qp.var_upper = Eigen::Vector2d(1e20, 1e20);
  // Unconstrained minimiser H^{-1}(-c) = (-2/7, 11/7) violates x0 >= 0.2; with x0 = 0.2: x1 = (6 - 0.2)/4 = 1.45,
  // x0 + x1 = 1.65 > 1, so both constraints bind: x = (0.2, 0.8).
  for (auto backend : {QpOptions::Backend::kIpopt, QpOptions::Backend::kCgal}) {
    QpOptions o;
    o.backend = backend;
    Eigen::VectorXd x = Eigen::Vector2d(0.0, 0.0);
    const QpSummary s = SolveQp(o, qp, &x);
    ASSERT_TRUE(s.solved) << s.message;
    EXPECT_NEAR(x[0], 0.2, 1e-7);
    EXPECT_NEAR(x[1], 0.8, 1e-7);
    EXPECT_NEAR(s.objective, 0.5 * (2 * 0.04 + 2 * 0.16 + 4 * 0.64) - 0.2 - 4.8, 1e-7);
  }
  qp.row_lower[0] = 2.0;  // x0 + x1 >= 2 with x0 <= 1, x1 <= 0: infeasible, both must say so
  qp.row_upper[0] = 1e20;
  qp.var_upper = Eigen::Vector2d(1.0, 0.0);
  for (auto backend : {QpOptions::Backend::kIpopt, QpOptions::Backend::kCgal}) {
    QpOptions o;
    o.backend = backend;
    Eigen::VectorXd x = Eigen::Vector2d(0.0, 0.0);
    const QpSummary s = SolveQp(o, qp, &x);
    EXPECT_FALSE(s.solved);
    EXPECT_TRUE(s.infeasible) << s.message;
  }
}

}  // namespace

// Output-error refinement on a low-noise valve rebuild: it must not worsen the simulation error of the
// estimation data (it only accepts decreasing steps), must keep every known-information constraint, must
// report the simulation error it reached (checked by an independent simulation here), and on held-out
// data it should not be worse than the SQP estimate it started from.
TEST(Esmaeilani, OutputErrorRefinementKeepsConstraintsAndDoesNotWorsenTheFit) {
  ValveCase valve;
  valve.output_noise_std = 0.05;
  valve.input_noise_std = 0.01;
  std::vector<Segment> est;
  for (unsigned k = 0; k < 9; ++k) est.push_back(valve.ClosingOperation(1000 + k, 150));
  const Segment val = valve.ClosingOperation(1009, 150);
  const Constraints cons = valve.KnownInformation();
  Options opt;
  opt.order = 3;
  opt.grid_f = 12;
  opt.grid_g = 12;
  opt.weight_state = 100;  // noise-scaled weights as in docs/esmaeilani.md
  opt.weight_output = 3;
  opt.weight_noise = 20;
  opt.max_iterations = 25;
  Summary sum;
  const EsmaeilaniModel sqp = Estimate(opt, est, cons, &sum);
  ASSERT_TRUE(sum.ok()) << sum.message;
  EXPECT_FALSE(sum.output_error.ran);  // off by default: the paper's estimator
  OutputErrorSummary oes;
  const EsmaeilaniModel m = RefineOutputError(opt, est, cons, sqp, &oes);
  ASSERT_TRUE(oes.ran);
  EXPECT_GT(oes.iterations, 0) << oes.message;
  EXPECT_EQ(oes.parameters, 12 + 12 + 3 + 3 + 2);  // steady-state starts: no initial-state unknowns
  auto sim_error = [&](const EsmaeilaniModel& mm) {
    double c = 0.0;
    for (const auto& s : est) {
      const auto yh = mm.Simulate(s.u);
      for (std::size_t t = 0; t < yh.size(); ++t) c += (s.y[t] - yh[t]) * (s.y[t] - yh[t]);
    }
    return c;
  };
  EXPECT_NEAR(oes.initial_cost, sim_error(sqp), 1e-9 * oes.initial_cost);
  EXPECT_NEAR(oes.final_cost, sim_error(m), 1e-9 * oes.initial_cost);
  EXPECT_LE(oes.final_cost, oes.initial_cost);
  // Known information still holds (same rows as the SQP: ranges, slopes, points, d = 0).
  const double tol = 1e-6;
  EXPECT_LE(oes.max_constraint_violation, tol);
  EXPECT_EQ(m.d, 0.0);
  for (std::size_t k = 0; k < m.f_values.size(); ++k) {
    EXPECT_GE(m.f_values[k], 0.0 - tol);
    EXPECT_LE(m.f_values[k], 100.0 + tol);
    if (k + 1 < m.f_values.size()) {
      const double s = (m.f_values[k + 1] - m.f_values[k]) / (m.u_grid[k + 1] - m.u_grid[k]);
      EXPECT_GE(s, -tol);
      EXPECT_LE(s, 5.0 + tol);
    }
  }
  for (std::size_t k = 0; k + 1 < m.ginv_values.size(); ++k)
    EXPECT_GE(m.ginv_values[k + 1] - m.ginv_values[k], -tol);
  for (const auto& p : cons.f.points) EXPECT_NEAR(m.F(p.at), p.lower, tol);
  for (const auto& p : cons.g_inverse.points) EXPECT_NEAR(m.Ginv(p.at), p.lower, tol);
  // Held-out operation (steady-state start, as in the validation of docs/esmaeilani.md).
  const double fit_sqp = fit_percent(val.y, sqp.Simulate(val.u)), fit_oe = fit_percent(val.y, m.Simulate(val.u));
  std::cout << "held-out fit: SQP " << fit_sqp << " %, refined " << fit_oe << " %; simulation error " << oes.initial_cost
            << " -> " << oes.final_cost << "\n";
  EXPECT_GE(fit_oe, fit_sqp - 0.5) << "SQP " << fit_sqp << " %, refined " << fit_oe << " %";
  EXPECT_GT(fit_oe, 97.0) << "SQP " << fit_sqp << " %, refined " << fit_oe << " %";
}

TEST(Esmaeilani, OutputErrorRefinementIsAnOptionOfEstimate) {
  ValveCase valve;
  std::vector<Segment> est;
  for (unsigned k = 0; k < 3; ++k) est.push_back(valve.ClosingOperation(2000 + k, 80));
  Options opt;
  opt.max_iterations = 3;
  opt.refine_output_error = true;
  opt.oe_max_iterations = 5;
  opt.oe_estimate_initial_states = true;
  Summary sum;
  const EsmaeilaniModel m = Estimate(opt, est, valve.KnownInformation(), &sum);
  ASSERT_TRUE(sum.ok()) << sum.message;
  ASSERT_TRUE(sum.output_error.ran);
  EXPECT_EQ(sum.output_error.parameters, 12 + 12 + 3 + 3 + 2 + 3 * 3);
  EXPECT_LE(sum.output_error.final_cost, sum.output_error.initial_cost);
  EXPECT_LE(sum.output_error.iterations, 5);
  ASSERT_EQ(m.initial_states.size(), 3u);
  opt.oe_max_iterations = 0;
  std::string err;
  EXPECT_FALSE(opt.IsValid(&err));
}
