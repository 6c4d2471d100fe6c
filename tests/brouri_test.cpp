// Tests of Brouri's backlash HW estimator (estimators/brouri): simulator exactness, operators, both
// stages noise-free and noisy, consistency in M and N, backlash-inverse input, and input errors.
#include <array>
#include <cmath>
#include <numbers>

#include <gtest/gtest.h>

#include "core/input_error.hpp"
#include "estimators/brouri/workflow.hpp"

namespace hw::brouri {
namespace {

TEST(BrouriPoly, ShiftRootsAndFit) {
  const std::vector<double> h = {0.0, 0.5, 0.0, -3.36, 0.0, 6.4};
  const auto q = PolyShift(h, -0.5);  // h(u - 0.5)
  for (double u : {-1.0, 0.2, 0.9}) EXPECT_NEAR(PolyEval(q, u), PolyEval(h, u - 0.5), 1e-12);
  const auto roots = PolyRealRoots(q);
  ASSERT_EQ(roots.size(), 1u);  // h vanishes only at 0
  EXPECT_NEAR(roots[0], 0.5, 1e-10);
  std::vector<double> x, y;
  for (int i = 0; i < 6; ++i) x.push_back(0.2 * (i + 1)), y.push_back(PolyEval(q, x.back()));
  const auto fit = PolyFit(x, y, 5);
  for (int i = 0; i <= 5; ++i) EXPECT_NEAR(fit[i], q[i], 1e-8);
}

TEST(BrouriSimulator, ZohDiscretisationIsExactForSteps) {
  // Step response of 0.1/((s+0.5)(s+0.2)) is 1 + (0.2 e^{-0.5t} - 0.5 e^{-0.2t}) / 0.3.
  TransferFunction g{{0.1}, {1.0, 0.7, 0.1}};
  const double ts = 0.37;
  ZohSystem zoh(g, ts);
  double worst = 0;
  for (int k = 0; k < 400; ++k) {
    const double t = k * ts;
    const double exact = 1.0 + (0.2 * std::exp(-0.5 * t) - 0.5 * std::exp(-0.2 * t)) / 0.3;
    worst = std::max(worst, std::abs(zoh.Step(1.0) - exact));
  }
  EXPECT_LT(worst, 1e-13);
}

TEST(BrouriSimulator, NormalisedModelHasTheSameOutput) {
  auto sys = BacklashHwSystem::PaperExample();
  sys.noise_std = 0;
  std::vector<double> u;
  for (int k = 0; k < 600; ++k) u.push_back(1.3 * std::sin(0.05 * k) + 0.4 * std::sin(0.011 * k));
  const auto a = Simulate(sys, u, 0.5, 1).y, b = Simulate(sys.Normalised(), u, 0.5, 1).y;
  for (std::size_t k = 0; k < u.size(); ++k) ASSERT_NEAR(a[k], b[k], 1e-11);
  EXPECT_NEAR(sys.Normalised().h[5], 6.4, 1e-12);  // eq. 30c
  EXPECT_NEAR(sys.Normalised().h[3], -3.36, 1e-12);
}

TEST(BrouriOperators, BacklashPathsAndLemma1) {
  MemoryOperator b(OperatorKind::kBacklash, {1.0, 0.5, 1.0, -0.5});
  EXPECT_DOUBLE_EQ(b.Step(1.0), 0.5);   // ascending border
  EXPECT_DOUBLE_EQ(b.Step(0.2), 0.5);   // inside: horizontal path
  EXPECT_DOUBLE_EQ(b.Step(-1.0), -0.5); // descending border
  // Lemma 1: each operator cancels the other, whichever is in front.
  for (auto kind : {OperatorKind::kBacklash, OperatorKind::kBacklashInverse}) {
    const BacklashParams p{1.1, 0.4, 0.9, -0.3};  // borders cross only far outside |z| <= 1.3
    NonlinearEstimate est;
    est.kind = kind;
    est.params = p;
    MemoryOperator pre = est.Precompensator();
    MemoryOperator f(kind, p);
    int reversals = 0, mismatches = 0;
    double last = 0, last_dir = 0;
    for (int k = 1; k < 500; ++k) {
      const double z = std::sin(0.07 * k) + 0.3 * std::sin(0.31 * k);
      const double dir = z > last ? 1 : -1;
      const bool reversal = k > 1 && dir != last_dir;
      reversals += reversal;
      const double v = f.Step(pre.Step(z));
      if (kind == OperatorKind::kBacklash) {
        ASSERT_NEAR(v, z, 1e-12) << "k=" << k;  // B o B_inv = I exactly (Lemma 1)
      } else if (k > 1 && std::abs(v - z) > 1e-12) {  // k = 1 aligns the two operators' rest states
        EXPECT_TRUE(reversal) << "backlash-inverse plant: mismatch away from a reversal at k=" << k;
        ++mismatches;
      }
      last = z, last_dir = dir;
    }
    if (kind == OperatorKind::kBacklashInverse) EXPECT_LE(mismatches, reversals);
  }
}

WorkflowConfig ShortConfig() {
  WorkflowConfig c = WorkflowConfig::Paper();
  c.steps = MakeStepPlan(c.steps.levels_up, c.steps.levels_down, c.steps.reset_level, 0.5, 130.0, 20);
  c.samples_per_period = 256;
  c.periods = 2;
  c.settling_time = 130.0;
  return c;
}

TEST(BrouriEstimator, NoiseFreeRecoversTheTruth) {
  auto sys = BacklashHwSystem::PaperExample();
  sys.noise_std = 0;
  const auto truth = sys.Normalised();
  const auto r = RunWorkflow(sys, ShortConfig(), 1);
  const auto& e = r.nonlinear;
  ASSERT_TRUE(r.nonlinear_summary.ok) << r.nonlinear_summary.message;
  EXPECT_EQ(e.kind, OperatorKind::kBacklash);
  EXPECT_EQ(e.j_a, 4);
  EXPECT_EQ(e.j_d, 5);
  EXPECT_NEAR(e.params.offset_up, 0.5, 1e-9);
  EXPECT_NEAR(e.params.slope_down, 1.0, 1e-8);
  EXPECT_NEAR(e.params.offset_down, -0.5, 1e-9);
  EXPECT_NEAR(e.d_down_coefficient, -0.5, 1e-8);  // the paper's reading agrees without noise
  for (int i = 0; i <= 5; ++i) EXPECT_NEAR(e.h[i], truth.h[i], 1e-7) << "h coefficient " << i;
  // Left: the staircase's images aliasing onto the fundamental, O(samples per period^-4).
  for (const auto& p : r.points) {
    const auto g = truth.g.Response(p.omega);
    EXPECT_NEAR(p.gain, std::abs(g), 5e-5) << "omega " << p.omega;
    EXPECT_NEAR(p.phase, -std::arg(g), 5e-5) << "omega " << p.omega;
    EXPECT_LT(p.fit_residual, 1e-3);
  }
}

TEST(BrouriEstimator, WithoutZohCorrectionThePhaseCarriesHalfASampleDelay) {
  auto sys = BacklashHwSystem::PaperExample();
  sys.noise_std = 0;
  auto c = ShortConfig();
  c.omegas = {0.2};
  c.samples_per_period = 32;  // coarse: the hold's Ts/2 delay is pi/32 rad
  c.frequency.zoh_correction = false;
  const auto raw = RunWorkflow(sys, c, 1).points[0];
  c.frequency.zoh_correction = true;
  const auto corrected = RunWorkflow(sys, c, 1).points[0];
  const double phi = -std::arg(sys.Normalised().g.Response(0.2));
  EXPECT_NEAR(raw.phase - phi, std::numbers::pi / 32, 2e-3);
  EXPECT_NEAR(corrected.phase, phi, 2e-3);
}

// RMS over seeds of the stage-1 and stage-2 errors, for given M and N.
struct Rms {
  double d_plus = 0, d_minus = 0, gain = 0, phase = 0;
};
Rms RmsErrors(int m, int n, int seeds) {
  const auto sys = BacklashHwSystem::PaperExample();
  const auto truth = sys.Normalised();
  auto c = ShortConfig();
  c.steps = MakeStepPlan(c.steps.levels_up, c.steps.levels_down, c.steps.reset_level, 0.5, 130.0, m);
  c.omegas = {0.05};
  c.periods = n;
  Rms r;
  const auto g = truth.g.Response(0.05);
  for (int s = 0; s < seeds; ++s) {
    const auto w = RunWorkflow(sys, c, 17 + 31 * s);
    r.d_plus += std::pow(w.nonlinear.params.offset_up - 0.5, 2);
    r.d_minus += std::pow(w.nonlinear.params.offset_down + 0.5, 2);
    r.gain += std::pow(w.points[0].gain - std::abs(g), 2);
    r.phase += std::pow(w.points[0].phase + std::arg(g), 2);
  }
  for (double* v : {&r.d_plus, &r.d_minus, &r.gain, &r.phase}) *v = std::sqrt(*v / seeds);
  return r;
}

TEST(BrouriEstimator, ErrorsShrinkAsAveragingGrows) {
  const Rms small = RmsErrors(10, 1, 12), large = RmsErrors(640, 16, 12);
  // Averaging 64x more samples should cut the errors ~8x; demand at least 3x.
  EXPECT_LT(large.d_plus, small.d_plus / 3) << small.d_plus << " -> " << large.d_plus;
  EXPECT_LT(large.d_minus, small.d_minus / 3) << small.d_minus << " -> " << large.d_minus;
  EXPECT_LT(large.gain, small.gain / 3) << small.gain << " -> " << large.gain;
  EXPECT_LT(large.phase, small.phase / 3) << small.phase << " -> " << large.phase;
}

TEST(BrouriReproduction, PaperSection6MatchesTheTablesAndTheTruth) {
  const auto sys = BacklashHwSystem::PaperExample();
  const auto c = WorkflowConfig::Paper();  // the paper's experiment: M = 100, N = 50, p = 5
  const auto r = RunWorkflow(sys, c, 1);
  const auto& e = r.nonlinear;
  EXPECT_EQ(e.j_a, 4);  // paper: j_a = 4
  EXPECT_EQ(e.j_d, 5);  // paper: j_d = 5
  // Table 1 (j = 5..10 ascending, 16..21 descending): our true X_j agree with the paper's rounded ones,
  // our X^_j with the paper's within 0.015 (its X^_10 = 0.26 is itself 0.013 off the truth 0.273).
  const std::vector<std::array<double, 3>> table1 = {
      {0.2, -0.075, -0.076}, {0.4, -0.047, -0.048}, {0.6, 0.047, 0.045},    {0.8, 0.075, 0.074},
      {1.0, 0.03, 0.028},    {1.2, 0.27, 0.26},     {0.0, 0.03, 0.031},     {-0.3, 0.075, 0.076},
      {-0.6, -0.047, -0.046}, {-1.0, -0.03, -0.029}, {-1.2, -0.27, -0.265}, {-1.4, -1.78, -1.775}};
  const auto truth_x = TrueHoldOutputs(sys, c.steps);
  for (std::size_t i = 0; i < table1.size(); ++i) {
    const std::size_t hold = i < 6 ? 5 + i : 16 + (i - 6);  // paper index j = our hold index
    ASSERT_DOUBLE_EQ(c.steps.Levels()[hold], table1[i][0]);
    const double xhat = i < 6 ? e.up[hold - 1].mean : e.down[hold - 1 - e.up.size()].mean;
    EXPECT_NEAR(truth_x[hold], table1[i][1], 0.0051) << "U = " << table1[i][0];
    EXPECT_NEAR(xhat, table1[i][2], 0.015) << "U = " << table1[i][0];
    EXPECT_NEAR(xhat, truth_x[hold], 0.005) << "U = " << table1[i][0];
  }
  // Backlash estimates: paper d+ = 0.503, S^d = 1.01, d- = -0.49; bar: within 0.02 of the truth.
  EXPECT_NEAR(e.params.offset_up, 0.5, 0.02);
  EXPECT_NEAR(e.params.slope_down, 1.0, 0.02);
  EXPECT_NEAR(e.params.offset_down, -0.5, 0.02);
  EXPECT_NEAR(e.params.offset_up, 0.503, 0.02);
  EXPECT_NEAR(e.params.slope_down, 1.01, 0.03);
  EXPECT_NEAR(e.params.offset_down, -0.49, 0.03);
  // Table 2: phi^ and |G^| within 0.05 of the truth and of the paper's estimates.
  const std::vector<std::array<double, 3>> table2 = {
      {0.01, 0.065, 1.01}, {0.02, 0.147, 0.97}, {0.05, 0.33, 0.95}, {0.1, 0.68, 0.89}, {0.2, 1.19, 0.68}};
  const auto truth = sys.Normalised();
  ASSERT_EQ(r.points.size(), table2.size());
  for (std::size_t i = 0; i < table2.size(); ++i) {
    const auto& p = r.points[i];
    const auto g = truth.g.Response(p.omega);
    EXPECT_NEAR(p.gain, std::abs(g), 0.05) << p.omega;
    EXPECT_NEAR(p.phase, -std::arg(g), 0.05) << p.omega;
    EXPECT_NEAR(p.phase, table2[i][1], 0.05) << p.omega;
    EXPECT_NEAR(p.gain, table2[i][2], 0.05) << p.omega;
  }
}

TEST(BrouriEstimator, BacklashInverseInputIsDetectedAndIdentified) {
  BacklashHwSystem sys = BacklashHwSystem::PaperExample();
  sys.kind = OperatorKind::kBacklashInverse;
  sys.backlash = {1.1, 0.3, 0.9, -0.2};
  sys.noise_std = 0;
  const auto truth = sys.Normalised();
  auto c = ShortConfig();
  // Every level on a line: border roots are -S^a d+ = -0.33 (up) and -S^d d- = 0.18 (down).
  c.steps = MakeStepPlan({-0.8, -0.6, -0.4, -0.2, 0.0, 0.2, 0.4}, {0.3, 0.1, -0.1, -0.3, -0.5, -0.7}, -1.0, 0.5, 130.0,
                         20);
  c.periods = 1;
  c.samples_per_period = 1024;
  const auto coarse = RunWorkflow(sys, c, 1);
  c.samples_per_period = 4096;
  const auto r = RunWorkflow(sys, c, 1);
  const auto& e = r.nonlinear;
  EXPECT_EQ(e.kind, OperatorKind::kBacklashInverse) << r.nonlinear_summary.message;
  EXPECT_EQ(e.j_a, 0);
  EXPECT_EQ(e.j_d, 0);
  EXPECT_NEAR(e.params.slope_up, truth.backlash.slope_up, 1e-6);
  EXPECT_NEAR(e.params.offset_up, truth.backlash.offset_up, 1e-6);
  EXPECT_NEAR(e.params.slope_down, truth.backlash.slope_down, 1e-6);
  EXPECT_NEAR(e.params.offset_down, truth.backlash.offset_down, 1e-6);
  for (std::size_t i = 0; i < r.points.size(); ++i) {
    const auto& p = r.points[i];
    const auto g = truth.g.Response(p.omega);
    // A backlash-inverse plant fed by a held (staircase) input follows its "up" line for one sample at
    // each reversal (see NonlinearEstimate::Precompensator): the error is O(1 / samples per period).
    EXPECT_NEAR(p.gain, std::abs(g), 1e-2) << p.omega;
    EXPECT_NEAR(p.phase, -std::arg(g), 1e-2) << p.omega;
    const double e_coarse = std::abs(coarse.points[i].gain - std::abs(g)), e_fine = std::abs(p.gain - std::abs(g));
    if (e_coarse > 1e-3) EXPECT_LT(e_fine, e_coarse / 2.5) << "4x finer sampling should cut the error ~4x";
  }
}

TEST(BrouriEstimator, JointRefitIsExactWithoutNoiseAndTightensSdWithNoise) {
  auto sys = BacklashHwSystem::PaperExample();
  auto c = ShortConfig();
  c.omegas = {0.05};
  c.nonlinear.joint_refit = true;
  sys.noise_std = 0;
  const auto exact = RunWorkflow(sys, c, 1);
  EXPECT_TRUE(exact.nonlinear.joint_refit);
  EXPECT_NEAR(exact.nonlinear.params.slope_down, 1.0, 1e-7);
  EXPECT_NEAR(exact.nonlinear.params.offset_down, -0.5, 1e-7);
  EXPECT_NEAR(exact.nonlinear.h[5], 6.4, 1e-5);
  sys.noise_std = 0.01;
  double rms_paper = 0, rms_joint = 0;
  for (int s = 0; s < 12; ++s) {
    c.nonlinear.joint_refit = false;
    rms_paper += std::pow(RunWorkflow(sys, c, 7 + s).nonlinear.params.slope_down - 1.0, 2);
    c.nonlinear.joint_refit = true;
    rms_joint += std::pow(RunWorkflow(sys, c, 7 + s).nonlinear.params.slope_down - 1.0, 2);
  }
  EXPECT_LT(rms_joint, rms_paper / 2) << "MSE of S^d: paper " << rms_paper / 12 << ", joint " << rms_joint / 12;
}

TEST(BrouriEstimator, LowerHarmonicGivesTheSameAnswerWithoutNoise) {
  auto sys = BacklashHwSystem::PaperExample();
  sys.noise_std = 0;
  auto c = ShortConfig();
  c.frequency.harmonic = 3;  // non-monotone P_3 candidates are resolved by all harmonics
  const auto r = RunWorkflow(sys, c, 1);
  for (const auto& p : r.points) {
    const auto g = sys.Normalised().g.Response(p.omega);
    EXPECT_EQ(p.harmonic, 3);
    EXPECT_NEAR(p.gain, std::abs(g), 1e-4) << p.omega;
    EXPECT_NEAR(p.phase, -std::arg(g), 1e-4) << p.omega;
  }
}

TEST(BrouriEstimator, EvenDegreeHAndThirdOrderGBeyondHalfATurn) {
  // h(w) = w + 0.8 w^2 + w^3 + 0.5 w^4: an even-degree h has a second real zero; here it is at -1.74,
  // outside the working range, so h^-1(0) = 0 holds where it matters (checked below).
  // G = 1 / ((s + 1)(s^2 + 0.6 s + 0.5)) has phase lag beyond pi at 1.5 rad/s.
  BacklashHwSystem sys;
  sys.kind = OperatorKind::kBacklash;
  sys.backlash = {0.8, 0.3, 1.1, -0.25};
  sys.g = {{1.0}, {1.0, 1.6, 1.1, 0.5}};
  sys.h = {0.0, 1.0, 0.8, 1.0, 0.5};
  const auto zeros = PolyRealRoots(sys.h);
  ASSERT_EQ(zeros.size(), 2u);
  ASSERT_LT(zeros[0], -1.7);
  const auto truth = sys.Normalised();
  auto c = ShortConfig();
  c.steps = MakeStepPlan({-0.4, -0.2, 0.0, 0.2, 0.4, 0.6, 0.8, 1.0}, {0.6, 0.2, -0.2, -0.4, -0.6, -0.8, -1.0},
                         -1.0, 0.5, 130.0, 20);
  c.nonlinear.degree = 4;
  c.omegas = {0.05, 0.3, 0.8, 1.5};
  c.amplitude = 0.5;
  const auto r = RunWorkflow(sys, c, 1);
  ASSERT_EQ(r.nonlinear.kind, OperatorKind::kBacklash) << r.nonlinear_summary.message;
  EXPECT_NEAR(r.nonlinear.params.offset_up, truth.backlash.offset_up, 1e-8);
  EXPECT_NEAR(r.nonlinear.params.slope_down, truth.backlash.slope_down, 1e-7);
  EXPECT_NEAR(r.nonlinear.params.offset_down, truth.backlash.offset_down, 1e-8);
  for (const auto& p : r.points) {
    const auto g = truth.g.Response(p.omega);
    double phi = -std::arg(g);
    if (phi < 0) phi += 2 * std::numbers::pi;  // lag of a 3rd-order system runs to 3 pi / 2
    EXPECT_NEAR(p.gain, std::abs(g), 1e-3) << p.omega;
    EXPECT_NEAR(p.phase, phi, 1e-3) << p.omega;
  }
  EXPECT_GT(r.points.back().phase, std::numbers::pi);  // unwrapped across the sweep
}

TEST(BrouriEstimator, DegreeIsSelectedFromTheData) {
  const auto sys = BacklashHwSystem::PaperExample();
  std::vector<double> up = {-0.6, -0.4, -0.2, 0.0};
  for (int i = 0; i <= 12; ++i) up.push_back(0.1 + 0.1 * i);
  std::vector<double> down = {1.1, 0.9, 0.7, 0.5, 0.3};
  for (int i = 0; i <= 12; ++i) down.push_back(0.1 - 0.125 * i);
  const auto plan = MakeStepPlan(up, down, -0.9, 0.5, 130.0, 200);
  const auto y = Simulate(sys, plan.Input(), plan.sample_time, 3).y;
  NonlinearOptions opt;  // degree 0: select
  Summary s;
  const auto e = EstimateFromSteps(plan, opt, {}, y, &s);
  EXPECT_EQ(e.degree, 5) << s.message;
  EXPECT_NEAR(e.params.offset_up, 0.5, 0.01);
}

TEST(BrouriEstimator, JsonRoundTripKeepsThePrecompensator) {
  auto sys = BacklashHwSystem::PaperExample();
  const auto c = ShortConfig();
  const auto r = RunWorkflow(sys, c, 5);
  const auto back = NonlinearEstimate::from_json(nlohmann::json::parse(r.nonlinear.to_json().dump()));
  EXPECT_EQ(back.kind, r.nonlinear.kind);
  EXPECT_EQ(back.h, r.nonlinear.h);
  const auto plan = SinePlan::from_json(nlohmann::json::parse(r.sines.to_json().dump()));
  EXPECT_EQ(plan.Input(0), r.sines.Input(0));
}

TEST(BrouriErrors, BadAndShortRecordingsAreExplained) {
  const auto c = ShortConfig();
  auto sys = BacklashHwSystem::PaperExample();
  auto y = Simulate(sys, c.steps.Input(), c.steps.sample_time, 1).y;
  y.resize(y.size() - 300);
  NonlinearOptions opt;
  opt.degree = 5;
  Summary s;
  try {
    EstimateFromSteps(c.steps, opt, {}, y, &s);
    FAIL() << "short recording accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("too short"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("record the remaining"), std::string::npos) << e.what();
  }
  // Too few border levels for the requested degree (eq. 11).
  const auto few = MakeStepPlan({-0.6, -0.2, 0.4, 0.8, 1.2}, {0.6, 0.0, -0.6, -1.2}, -0.9, 0.5, 130.0, 20);
  const auto yf = Simulate(sys, few.Input(), 0.5, 1).y;
  try {
    EstimateFromSteps(few, opt, {}, yf, &s);
    FAIL() << "degree 5 from 3 border points accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("p + 1"), std::string::npos) << e.what();
  }
  // A recorded input that is not the planned one.
  auto u = c.steps.Input();
  u[700] += 0.1;
  EXPECT_THROW(EstimateFromSteps(c.steps, opt, u, Simulate(sys, u, 0.5, 1).y, &s), InputError);
  // Plans that cannot work.
  EXPECT_THROW(MakeStepPlan({0.2, 0.1}, {0.0, -0.5}, -1.0, 0.5, 80, 20), InputError);
  EXPECT_THROW(MakeStepPlan({0.1, 0.2}, {0.0, -0.5}, 0.5, 0.5, 80, 20), InputError);
  // A sine recording with too few periods.
  const auto r = RunWorkflow(sys, c, 1);
  const auto u0 = r.sines.Input(0);
  auto y0 = Simulate(sys, u0, r.sines.experiments[0].sample_time(), 1).y;
  y0.resize(y0.size() / 2);
  FrequencyPoint pt;
  try {
    pt = EstimateFromSine(r.sines, 0, {}, {}, y0, &s);
    FAIL() << "short sine recording accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("averaged periods"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace hw::brouri
