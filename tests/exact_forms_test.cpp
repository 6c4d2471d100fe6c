// Parameter forms (exact/parameter_forms.hpp): thin directions from points, the propagation between form and
// axis ranges, the lifted LP's rows for a form range, and soundness of whole runs that use forms.
#include <algorithm>
#include <random>

#include <gtest/gtest.h>

#include "exact/branch_and_bound.hpp"
#include "exact/clp_solver.hpp"
#include "exact/parameter_forms.hpp"
#include "exact/exact_bounds.hpp"
#include "exact/membership.hpp"
#include "random_hw.hpp"

namespace hw::exact {
namespace {

// A random instance of exactly n samples with na = 2.
testing::RandomHwInstance SecondOrderInstance(uint64_t first_seed, int samples) {
  testing::RandomHwOptions opts;
  opts.min_samples = samples, opts.max_samples = samples;
  for (uint64_t seed = first_seed;; ++seed) {
    auto inst = testing::MakeRandomHwInstance(seed, opts);
    if (inst.structure.na == 2) return inst;
  }
}

ParamBox BoxAround(const LiftedData& d, const std::vector<double>& theta, double a_width, double other_width) {
  ParamBox box;
  for (int k = 0; k < d.layout.count(); ++k) {
    const bool is_a = k >= d.layout.a_begin && k < d.layout.a_begin + d.structure.na;
    box.emplace_back(theta[k] - (is_a ? a_width : other_width), theta[k] + (is_a ? a_width : other_width));
  }
  return box;
}

TEST(DynamicsForms, ThePointsThinDirectionIsFoundAndAnIsotropicCloudHasNone) {
  const auto inst = SecondOrderInstance(1, 40);
  const LiftedData d = MakeLiftedData(inst.structure, inst.data);
  const int a0 = d.layout.a_begin;
  std::mt19937 rng(3);
  std::normal_distribution<double> n(0.0, 1.0);
  std::vector<std::vector<double>> strip, cloud;
  for (int p = 0; p < 12; ++p) {
    std::vector<double> theta = inst.theta;
    const double along = n(rng) * 1e-3, across = n(rng) * 1e-5;  // a strip along (1, 1)
    theta[a0] += along + across;
    theta[a0 + 1] += along - across;
    strip.push_back(theta);
    theta = inst.theta;
    theta[a0] += n(rng) * 1e-3;
    theta[a0 + 1] += n(rng) * 1e-3;
    cloud.push_back(theta);
  }
  const auto forms = ThinDirections(d, strip);
  ASSERT_EQ(forms.size(), 1u);
  EXPECT_EQ(forms[0].coef[0], 1.0);
  EXPECT_NEAR(forms[0].coef[1], -1.0, 0.02);  // twelve points estimate the direction
  EXPECT_TRUE(ThinDirections(d, cloud).empty());
  EXPECT_TRUE(ThinDirections(d, {strip[0], strip[1]}).empty());  // too few points
}

TEST(DynamicsForms, PropagationNarrowsBothWaysAndKeepsEveryPointOfBoth) {
  const auto inst = SecondOrderInstance(2, 40);
  LiftedData d = MakeLiftedData(inst.structure, inst.data);
  d.forms = {{FormBlock::kDynamics, {1.0, -1.0}}};
  const int a0 = d.layout.a_begin, f = d.layout.count();
  ParamBox box(d.layout.count(), Interval(0.0, 1.0));
  box[a0] = Interval(1.0, 2.0);
  box[a0 + 1] = Interval(0.5, 1.0);
  box = WithFormRanges(d, box);
  EXPECT_LE(box[f].lo, 0.0);
  EXPECT_GE(box[f].hi, 1.5);
  box[f] = Interval(0.9, 1.0);  // a1 - a2 in [0.9, 1]: a1 <= 2.0 and a1 >= 1.4
  PropagateForms(d, box);
  EXPECT_NEAR(box[a0].lo, 1.4, 1e-12);
  EXPECT_LE(box[a0].lo, 1.4);
  EXPECT_NEAR(box[a0].hi, 2.0, 1e-12);
  EXPECT_NEAR(box[a0 + 1].hi, 1.0, 1e-12);
  // Every pair with a1 - a2 in the form range and both in the old box is still inside.
  for (double a1 = 1.0; a1 <= 2.0; a1 += 0.01)
    for (double a2 = 0.5; a2 <= 1.0; a2 += 0.01)
      if (a1 - a2 >= 0.9 && a1 - a2 <= 1.0) {
        EXPECT_TRUE(box[a0].contains(a1)) << a1;
        EXPECT_TRUE(box[a0 + 1].contains(a2)) << a2;
      }
}

TEST(DynamicsForms, AFormRangeAroundTheTruthIsKeptAndOneBesideItIsPruned) {
  const auto inst = SecondOrderInstance(3, 80);
  LiftedData d = MakeLiftedData(inst.structure, inst.data);
  d.forms = {{FormBlock::kDynamics, {1.0, -1.0}}};
  const int a0 = d.layout.a_begin, f = d.layout.count();
  const double truth = inst.theta[a0] - inst.theta[a0 + 1];
  ClpSolver clp;
  BoxEvaluationOptions ev;
  ev.cheap_window = 0;
  ParamBox box = WithFormRanges(d, BoxAround(d, inst.theta, 0.05, 0.5));
  box[f] = Interval(truth - 1e-6, truth + 1e-6);  // a thin range: the form rows are tight around the truth
  PropagateForms(d, box);
  EXPECT_EQ(TestBoxEmpty(d, box, ev, clp).verdict, BoxVerdict::kKept) << inst.description;
  box[f] = Interval(truth + 0.04, truth + 0.05);  // inside the axis box, far from D
  const BoxEvaluation e = TestBoxEmpty(d, box, ev, clp);
  EXPECT_EQ(e.verdict, BoxVerdict::kPruned) << inst.description;
}

struct FormRunCounts {
  int with_forms = 0, with_input_forms = 0, members = 0;
};

// Whole runs on random systems [first_seed, end_seed) with `forms` (a generous thin share, so most second- and
// third-order systems get one): the truth and independently found points of D (random steps from the truth,
// each checked by the membership LP) stay inside every interval.
FormRunCounts ExpectRunsContainTruthAndMembers(uint64_t first_seed, uint64_t end_seed, FormOptions forms,
                                               unsigned rng_seed) {
  FormRunCounts counts;
  std::mt19937 rng(rng_seed);
  std::normal_distribution<double> step(0.0, 1.0);
  ClpSolver clp;
  for (uint64_t seed = first_seed; seed < end_seed; ++seed) {
    testing::RandomHwOptions opts;
    opts.min_samples = 40, opts.max_samples = 70;
    const auto inst = testing::MakeRandomHwInstance(seed, opts);
    const LiftedData d = MakeLiftedData(inst.structure, inst.data);
    const ParamBox start = BoxAround(d, inst.theta, 0.02, 0.3);
    ExactBoundsOptions o;
    o.executor = std::make_shared<sdp::InProcessExecutor>();
    o.prune.max_levels = 4;
    o.search.lp_budget = 4;
    o.sweeps = 2;
    o.evaluation.cheap_window = 0;
    o.forms = forms;
    o.forms.thin_share = 0.95;
    const ExactBoundsSummary s = ComputeExactBounds(o, inst.structure, inst.data, start);
    EXPECT_FALSE(s.invalidated) << inst.description;
    if (s.invalidated) continue;
    counts.with_forms += !s.forms.empty();
    counts.with_input_forms += std::any_of(s.forms.begin(), s.forms.end(),
                                           [](const auto& f) { return f.block != FormBlock::kDynamics; });
    std::vector<std::vector<double>> points = {inst.theta};
    for (int trial = 0; trial < 8; ++trial) {
      std::vector<double> p = inst.theta;
      for (double& v : p) v += 1e-3 * step(rng) * std::max(1.0, std::abs(v));
      if (CheckMembership(d, p, clp).member) points.push_back(p);
    }
    counts.members += static_cast<int>(points.size());
    for (const auto& p : points)
      for (int k = 0; k < d.layout.count(); ++k) {
        if (!start[k].contains(p[k])) continue;
        EXPECT_LE(s.intervals[k].lower.value, p[k]) << inst.description << " " << d.layout.names[k];
        EXPECT_GE(s.intervals[k].upper.value, p[k]) << inst.description << " " << d.layout.names[k];
      }
  }
  return counts;
}

TEST(DynamicsForms, RunsWithFormsContainTheTruthAndIndependentMembers) {
  FormOptions dynamics_only;
  dynamics_only.gain = false;
  const FormRunCounts counts = ExpectRunsContainTruthAndMembers(201, 221, dynamics_only, 7);
  EXPECT_GE(counts.with_forms, 5);
  EXPECT_GT(counts.members, 20);
}

// A random instance of exactly n samples with at least two b_j and two free gammas.
testing::RandomHwInstance InputSideInstance(uint64_t first_seed, int samples) {
  testing::RandomHwOptions opts;
  opts.min_samples = samples, opts.max_samples = samples;
  for (uint64_t seed = first_seed;; ++seed) {
    auto inst = testing::MakeRandomHwInstance(seed, opts);
    const auto lay = dss::MakeLayout(inst.structure);
    if (lay.count() - lay.b_begin >= 2 && lay.num_gamma >= 2) return inst;
  }
}

TEST(ParameterForms, GainAndShapeDirectionsAreFoundInTheirBlocksAndRoundTripThroughJson) {
  const auto inst = InputSideInstance(11, 40);
  const LiftedData d = MakeLiftedData(inst.structure, inst.data);
  const int b0 = d.layout.b_begin, g0 = d.layout.gamma_begin;
  std::mt19937 rng(5);
  std::normal_distribution<double> n(0.0, 1.0);
  std::vector<std::vector<double>> points;
  for (int p = 0; p < 12; ++p) {  // strips along (1, 2) in (b_j0, b_j0+1) and along (1, -1) in (gamma_2, gamma_3)
    std::vector<double> theta = inst.theta;
    const double b_along = n(rng) * 1e-3, g_along = n(rng) * 1e-3;
    theta[b0] += b_along + n(rng) * 1e-6;
    theta[b0 + 1] += 2 * b_along;
    theta[g0] += g_along + n(rng) * 1e-6;
    theta[g0 + 1] -= g_along;
    for (int k = 0; k < d.layout.count(); ++k)  // every other entry spread as widely (no other block is thin)
      if (k != b0 && k != b0 + 1 && k != g0 && k != g0 + 1) theta[k] += n(rng) * 1e-3;
    points.push_back(theta);
  }
  FormOptions only_dynamics, input;
  only_dynamics.gain = false;
  input.gain = input.shape = true;
  EXPECT_TRUE(ThinDirections(d, points, only_dynamics).empty());
  const auto forms = ThinDirections(d, points, input);
  ASSERT_GE(forms.size(), 2u);
  const auto gain = std::find_if(forms.begin(), forms.end(), [](const auto& f) { return f.block == FormBlock::kGain; });
  const auto shape = std::find_if(forms.begin(), forms.end(), [](const auto& f) { return f.block == FormBlock::kShape; });
  ASSERT_NE(gain, forms.end());
  ASSERT_NE(shape, forms.end());
  EXPECT_NEAR(gain->coef[1] / gain->coef[0], -0.5, 0.02);  // across (1, 2)
  EXPECT_NEAR(shape->coef[1] / shape->coef[0], 1.0, 0.02);  // across (1, -1)
  EXPECT_EQ(FormsFromJson(FormsToJson(forms)), forms);
  // A dynamics form is a bare list (the format of earlier results), read back as one.
  const std::vector<ParameterForm> dynamics = {{FormBlock::kDynamics, {1.0, -0.5}}};
  EXPECT_TRUE(FormsToJson(dynamics)[0].is_array());
  EXPECT_EQ(FormsFromJson(nlohmann::json::parse("[[1.0, -0.5]]")), dynamics);
  EXPECT_THROW(FormsFromJson(nlohmann::json::parse(R"([{"block": "alpha", "coef": [1]}])")), std::invalid_argument);
}

// The envelopes of a gain form with each gamma_k: a thin form range around the truth keeps the truth's box, and
// it bounds beta_1k - beta_2k = (b_1 - b_2) gamma_k where the axis ranges and the form's definition alone do not.
TEST(ParameterForms, AThinGainFormRangeKeepsTheTruthAndTiesTheBetasToIt) {
  const auto inst = InputSideInstance(21, 80);
  LiftedData d = MakeLiftedData(inst.structure, inst.data);
  const int b0 = d.layout.b_begin, f = d.layout.count();
  d.forms = {{FormBlock::kGain, std::vector<double>(d.layout.count() - b0, 0.0)}};
  d.forms[0].coef[0] = 1.0, d.forms[0].coef[1] = -1.0;
  const double truth = inst.theta[b0] - inst.theta[b0 + 1];
  ClpSolver clp;
  BoxEvaluationOptions ev;
  ev.cheap_window = 0;
  const ParamBox wide = WithFormRanges(d, BoxAround(d, inst.theta, 1e-4, 0.05));
  ParamBox thin = wide;
  thin[f] = Interval(truth - 1e-6, truth + 1e-6);
  EXPECT_EQ(TestBoxEmpty(d, thin, ev, clp).verdict, BoxVerdict::kKept) << inst.description;
  // min of beta_{j0,2} - beta_{j0+1,2} over the bounding LP, with the form's range wide and thin.
  auto min_difference = [&](const ParamBox& box) {
    LiftedLp lp = BuildLiftedLp(d, box, WholeRecord(d), LiftedForm::kBounding);
    std::fill(lp.lp.obj.begin(), lp.lp.obj.end(), 0.0);
    lp.lp.obj[lp.beta_col[0][1]] = 1.0;
    lp.lp.obj[lp.beta_col[1][1]] = -1.0;
    const LpResult r = clp.Solve(lp.lp, {}, LpSolveOptions{});
    EXPECT_EQ(r.status, LpStatus::kOptimal) << inst.description;
    return r.objective;
  };
  const double gamma2 = inst.theta[d.layout.gamma_begin];
  const double with_wide = min_difference(wide), with_thin = min_difference(thin);
  EXPECT_LE(with_thin, truth * gamma2 + 1e-9);  // the truth's value is feasible
  // The thin range closes most of the gap between the wide range's bound and the truth's value (0.80 on this
  // instance; 0.25 through the form's definition row alone, without its envelopes).
  EXPECT_GT((with_thin - with_wide) / (truth * gamma2 - with_wide), 0.5) << inst.description;
}

// Whole runs with gain and shape forms besides the dynamics forms.
TEST(ParameterForms, RunsWithInputFormsContainTheTruthAndIndependentMembers) {
  FormOptions input;
  input.gain = input.shape = true;
  const FormRunCounts counts = ExpectRunsContainTruthAndMembers(231, 243, input, 9);
  EXPECT_GE(counts.with_input_forms, 4);
  EXPECT_GT(counts.members, 12);
}

}  // namespace
}  // namespace hw::exact
