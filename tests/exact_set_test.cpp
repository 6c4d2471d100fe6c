// The exact-set engine (exact/): safe LP bounds, the lifted relaxation, branch and bound, soundness on many
// random systems, and bounds that hold against an LP backend that lies.
#include <cmath>
#include <cstdio>
#include <fstream>
#include <random>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "exact/branch_and_bound.hpp"
#include "exact/clp_solver.hpp"
#include "exact/exact_bounds.hpp"
#include "exact/glpk_solver.hpp"
#include "exact/membership.hpp"
#include "exact/safe_bound.hpp"
#include "random_hw.hpp"
#include "small_lps.hpp"
#include "test_support.hpp"

namespace hw::exact {
namespace {

// A box around the truth: +-a_width on the a_i, +-other_width elsewhere.
ParamBox BoxAround(const LiftedData& d, const std::vector<double>& theta, double a_width, double other_width) {
  ParamBox box;
  for (int k = 0; k < d.layout.count(); ++k) {
    const bool is_a = k >= d.layout.a_begin && k < d.layout.a_begin + d.structure.na;
    const double w = is_a ? a_width : other_width;
    box.emplace_back(theta[k] - w, theta[k] + w);
  }
  return box;
}

// A random instance of exactly n samples.
testing::RandomHwInstance InstanceOf(uint64_t seed, int samples) {
  testing::RandomHwOptions opts;
  opts.min_samples = samples, opts.max_samples = samples;
  return testing::MakeRandomHwInstance(seed, opts);
}

ExactBoundsOptions SmallRunOptions() {
  ExactBoundsOptions o;
  o.executor = std::make_shared<sdp::InProcessExecutor>();
  o.prune.max_levels = 4;
  o.search.lp_budget = 3;
  o.sweeps = 1;
  o.inner_hull = false;
  o.evaluation.cheap_window = 0;
  return o;
}

TEST(SafeBound, EqualsTheLpOptimumOnASmallProblemAndNeverExceedsIt) {
  LpProblem lp = testing_lps::TwoRowLp();  // optimum 1.4
  ClpSolver clp;
  const LpResult r = clp.Solve(lp, {}, {});
  ASSERT_EQ(r.status, LpStatus::kOptimal);
  EXPECT_NEAR(r.objective, 1.4, 1e-12);
  const double safe = SafeLowerBound(lp, r.duals);
  EXPECT_LE(safe, 1.4 + 1e-15);
  EXPECT_GT(safe, 1.4 - 1e-12);
  // Any dual vector gives a valid (weaker) bound.
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> dist(-2, 2);
  for (int trial = 0; trial < 200; ++trial) EXPECT_LE(SafeLowerBound(lp, {dist(rng), dist(rng)}), 1.4 + 1e-15);
  // A coefficient known only to +-0.1 weakens the bound, as it must.
  lp.entries[0].radius = 0.1;
  EXPECT_LT(SafeLowerBound(lp, r.duals), safe);
}

TEST(LiftedLp, TheTruthsBoxIsNeverProvenEmptyAndABoxFarAwayIs) {
  const auto inst = InstanceOf(7, 80);
  const LiftedData d = MakeLiftedData(inst.structure, inst.data);
  ClpSolver clp;
  BoxEvaluationOptions ev;
  ev.cheap_window = 30;
  const ParamBox around = BoxAround(d, inst.theta, 1e-3, 1.0);
  EXPECT_EQ(TestBoxEmpty(d, around, ev, clp).verdict, BoxVerdict::kKept) << inst.description;
  ParamBox far = around;
  far[d.layout.a_begin].lo += 0.3, far[d.layout.a_begin].hi += 0.3;
  const BoxEvaluation e = TestBoxEmpty(d, far, ev, clp);
  ASSERT_EQ(e.verdict, BoxVerdict::kPruned) << inst.description;
  EXPECT_GT(e.certificate->residual_lower_bound, 0.0);
}

// A gamma's bound is a ratio found by Dinkelbach steps (one LP each). Started from the ratio a first evaluation
// reached — what a child box inherits from its parent — one LP certifies the same bound to the accuracy asked.
TEST(BoxEvaluation, AGammaRatioStartedNearItsAnswerNeedsOneLp) {
  for (uint64_t seed = 1; seed <= 40; ++seed) {
    const auto inst = InstanceOf(seed, 80);
    const LiftedData d = MakeLiftedData(inst.structure, inst.data);
    if (d.layout.num_gamma == 0) continue;
    const ParamBox box = BoxAround(d, inst.theta, 1e-3, 0.05);
    bool b_signed = false;  // the ratio needs some b_j of one sign over the box
    for (int k = d.layout.b_begin; k < d.layout.count(); ++k) b_signed |= box[k].lo > 0 || box[k].hi < 0;
    if (!b_signed) continue;
    ClpSolver clp;
    BoxEvaluationOptions ev;
    ev.cheap_window = 0;
    const Objective max_gamma{d.layout.gamma_begin, true};
    const BoxEvaluation from_middle = BoundObjective(d, box, max_gamma, ev, clp);
    ASSERT_TRUE(from_middle.bound.has_value()) << inst.description;
    ASSERT_GE(from_middle.lps, 2) << inst.description;  // the middle of the box is not the answer
    const BoxEvaluation from_answer =
        BoundObjective(d, box, max_gamma, ev, clp, {}, GammaRatio::kLargest, 0, from_middle.lp_value);
    ASSERT_TRUE(from_answer.bound.has_value()) << inst.description;
    EXPECT_EQ(from_answer.lps, 1) << inst.description;
    EXPECT_NEAR(*from_answer.bound, *from_middle.bound, 1e-4 * (box[max_gamma.parameter].hi - box[max_gamma.parameter].lo));
    EXPECT_GE(*from_answer.bound, inst.theta[max_gamma.parameter]) << inst.description;
    return;
  }
  FAIL() << "no random instance with a gamma and a signed b_j in seeds 1-40";
}

TEST(ExactBounds, AnEndpointShortOfItsTargetSpendsTheBudgetTheOthersLeave) {
  // Inner hull [0, 1]: at ratio 1.25 each end may lie 0.125 outside it.
  auto interval = [](double lo, double hi) {
    ExactInterval iv;
    iv.lower.value = lo;
    iv.upper.value = hi;
    iv.inner = std::make_pair(0.0, 1.0);
    return iv;
  };
  EXPECT_FALSE(ShortOfTarget(interval(-0.1, 1.1), false, 1.25));
  EXPECT_TRUE(ShortOfTarget(interval(-0.2, 1.1), false, 1.25));   // ratio 1.3: the lower end keeps it there
  EXPECT_FALSE(ShortOfTarget(interval(-0.2, 1.1), true, 1.25));
  EXPECT_TRUE(ShortOfTarget(interval(-0.1, 1.2), true, 1.25));
  EXPECT_TRUE(WithinTarget(interval(-0.2, 1.0), 1.25));            // ratio 1.2: no end is short
  EXPECT_FALSE(ShortOfTarget(interval(-0.2, 1.0), false, 1.25));
  ExactInterval without_inner = interval(-0.1, 1.1);
  without_inner.inner.reset();
  EXPECT_FALSE(WithinTarget(without_inner, 1.25));
  EXPECT_TRUE(ShortOfTarget(without_inner, true, 1.25));

  // 8 intervals = 16 endpoints.
  std::vector<ExactInterval> ivs(8, interval(-0.1, 1.1));
  EXPECT_TRUE(AllWithinTarget(ivs, 1.25));                // no further sweep needed
  EXPECT_EQ(ShortEndpointBudget(ivs, 1.25, 10, 4), 10);  // nobody short: the plain budget
  ivs[3] = interval(-0.2, 1.1);                           // one short endpoint: 16x, capped at 4x
  EXPECT_FALSE(AllWithinTarget(ivs, 1.25));
  EXPECT_EQ(ShortEndpointBudget(ivs, 1.25, 10, 4), 40);
  EXPECT_EQ(ShortEndpointBudget(ivs, 1.25, 10, 1), 10);   // cap 1: off
  for (int k = 0; k < 5; ++k) ivs[k] = interval(-0.2, 1.1);  // 5 short: 16 / 5 = 3 times
  EXPECT_EQ(ShortEndpointBudget(ivs, 1.25, 10, 4), 30);
  for (auto& iv : ivs) iv = interval(-0.5, 1.5);         // all short (the first sweep): the plain budget
  EXPECT_EQ(ShortEndpointBudget(ivs, 1.25, 10, 4), 10);
}

TEST(LpBackends, ClpAndGlpkAgreeOnTheOptimumAndBothDualsCertify) {
  const auto inst = InstanceOf(11, 80);
  const LiftedData d = MakeLiftedData(inst.structure, inst.data);
  const ParamBox box = BoxAround(d, inst.theta, 1e-2, 1.0);
  LiftedLp lifted = BuildLiftedLp(d, box, WholeRecord(d), LiftedForm::kBounding);
  std::vector<double> weights(d.layout.count(), 0.0);
  weights[d.layout.b_begin] = 1.0;  // min b_first
  lifted.SetParameterObjective(weights);
  ClpSolver clp;
  GlpkSolver glpk;
  const LpResult rc = clp.Solve(lifted.lp, {}, {}), rg = glpk.Solve(lifted.lp, {}, {});
  ASSERT_EQ(rc.status, LpStatus::kOptimal) << rc.message;
  ASSERT_EQ(rg.status, LpStatus::kOptimal) << rg.message;
  EXPECT_NEAR(rc.objective, rg.objective, 1e-6 * (1.0 + std::abs(rc.objective)));
  for (const LpResult* r : {&rc, &rg}) {
    const double safe = SafeLowerBound(lifted.lp, r->duals);
    EXPECT_LE(safe, r->objective + 1e-9);
    EXPECT_GT(safe, r->objective - 1e-6 * (1.0 + std::abs(r->objective)));
    EXPECT_LE(safe, inst.theta[d.layout.b_begin]) << inst.description;  // the truth is in the box
  }
  // GLPK's own basis warm-starts it: the same problem again needs no pivot.
  EXPECT_EQ(glpk.Solve(lifted.lp, rg.basis, {}).iterations, 0);
  // Emptiness of a far box is certified from either backend's duals.
  ParamBox far = box;
  far[d.layout.a_begin].lo += 0.3, far[d.layout.a_begin].hi += 0.3;
  BoxEvaluationOptions ev;
  ev.cheap_window = 0;
  EXPECT_EQ(TestBoxEmpty(d, far, ev, glpk).verdict, BoxVerdict::kPruned);
  EXPECT_EQ(TestBoxEmpty(d, box, ev, glpk).verdict, BoxVerdict::kKept);
}

TEST(ExactBounds, TheGlpkBackendContainsTheTruthAsClpDoes) {
  const auto inst = InstanceOf(5, 80);
  const LiftedData d = MakeLiftedData(inst.structure, inst.data);
  ExactBoundsOptions o = SmallRunOptions();
  o.lp_solver = "glpk";
  const auto s = ComputeExactBounds(o, inst.structure, inst.data, BoxAround(d, inst.theta, 0.05, 1.0));
  for (int k = 0; k < d.layout.count(); ++k) {
    EXPECT_LE(s.intervals[k].lower.value, inst.theta[k]) << d.layout.names[k];
    EXPECT_GE(s.intervals[k].upper.value, inst.theta[k]) << d.layout.names[k];
  }
  std::string error;
  o.lp_solver = "highs";
  EXPECT_FALSE(o.IsValid(&error));
  EXPECT_NE(error.find("clp, glpk"), std::string::npos) << error;
}

// An LP backend that answers "optimal" with random duals and a made-up value, or "infeasible" without duals.
class LyingSolver : public LpSolver {
 public:
  explicit LyingSolver(bool claim_infeasible) : claim_infeasible_(claim_infeasible) {}
  std::string name() const override { return "liar"; }
  LpResult Solve(const LpProblem& p, const LpBasis&, const LpSolveOptions&) override {
    LpResult r;
    r.status = claim_infeasible_ ? LpStatus::kInfeasible : LpStatus::kOptimal;
    r.objective = 1e6;
    r.primal.assign(p.num_cols(), 0.0);
    if (!claim_infeasible_) {
      std::uniform_real_distribution<double> dist(-5, 5);
      for (int i = 0; i < p.num_rows(); ++i) r.duals.push_back(dist(rng_));
    }
    return r;
  }

 private:
  bool claim_infeasible_;
  std::mt19937 rng_{3};
};

// Where an a_i endpoint's LP overreaches D it rests on beta = b*gamma: kDynamicsGamma lets that endpoint halve
// a gamma (when it is the widest against D's known extent); every other endpoint still halves the dynamics.
TEST(BranchAndBound, AnAEndpointUnderDynamicsGammaHalvesTheGammaWidestAgainstDsExtent) {
  testing::RandomHwInstance inst;
  for (uint64_t seed = 1;; ++seed) {
    inst = InstanceOf(seed, 40);
    if (MakeLiftedData(inst.structure, inst.data).layout.num_gamma > 0) break;
  }
  const LiftedData d = MakeLiftedData(inst.structure, inst.data);
  const auto& lay = d.layout;
  const ParamBox box = BoxAround(d, inst.theta, 0.01, 0.1);
  ParamBox extent = box;  // D known to fill the box in every entry but the gammas, a tenth of theirs
  for (int k = lay.gamma_begin; k < lay.gamma_begin + lay.num_gamma; ++k)
    extent[k] = Interval(inst.theta[k] - 0.01, inst.theta[k] + 0.01);
  const auto is_gamma = [&](int k) { return k >= lay.gamma_begin && k < lay.gamma_begin + lay.num_gamma; };
  const auto is_a = [&](int k) { return k >= lay.a_begin && k < lay.a_begin + d.structure.na; };
  EXPECT_TRUE(is_gamma(SplitEntry(d, box, box, lay.a_begin, EndpointSplit::kDynamicsGamma, &extent))) << inst.description;
  EXPECT_TRUE(is_a(SplitEntry(d, box, box, lay.a_begin, EndpointSplit::kDynamics, &extent))) << inst.description;
  EXPECT_TRUE(is_a(SplitEntry(d, box, box, lay.b_begin, EndpointSplit::kDynamicsGamma, &extent))) << inst.description;
  EndpointSplit parsed = EndpointSplit::kDynamics;
  EXPECT_TRUE(ParseEndpointSplit("dynamics-gamma", &parsed));
  EXPECT_EQ(parsed, EndpointSplit::kDynamicsGamma);
}

TEST(BranchAndBound, ALyingLpBackendNeitherDropsTheTruthsBoxNorExcludesTheTruth) {
  const auto inst = InstanceOf(11, 60);
  const LiftedData d = MakeLiftedData(inst.structure, inst.data);
  const ParamBox start = BoxAround(d, inst.theta, 0.05, 0.5);
  BoxEvaluationOptions ev;
  ObjectiveSearchOptions so;
  so.lp_budget = 6;
  for (bool claim_infeasible : {true, false}) {
    LyingSolver liar(claim_infeasible);
    EXPECT_EQ(TestBoxEmpty(d, start, ev, liar).verdict, BoxVerdict::kKept);
    for (int k = 0; k < d.layout.count(); ++k)
      for (bool maximise : {false, true}) {
        const auto r = SearchObjective(d, start, {start}, {k, maximise}, std::nullopt, 0.0, so, ev, liar);
        ASSERT_FALSE(r.empty) << inst.description;
        if (maximise) {
          EXPECT_GE(r.bound, inst.theta[k]) << inst.description << " parameter " << k;
        } else {
          EXPECT_LE(r.bound, inst.theta[k]) << inst.description << " parameter " << k;
        }
      }
  }
}

// Points of D found independently of the engine: the truth and random perturbations of it that the exact
// membership LP accepts.
std::vector<std::vector<double>> IndependentMembers(const LiftedData& d, const testing::RandomHwInstance& inst,
                                                    const ParamBox& start, LpSolver& solver, std::mt19937& rng) {
  std::vector<std::vector<double>> members = {inst.theta};
  std::normal_distribution<double> step(0.0, 1.0);
  for (int trial = 0; trial < 12; ++trial) {
    std::vector<double> p = inst.theta;
    const double scale = std::pow(10.0, -2.0 - trial % 3);
    for (int k = 0; k < d.layout.count(); ++k) p[k] += scale * step(rng) * std::max(1.0, std::abs(p[k]));
    bool inside = true;
    for (int k = 0; k < d.layout.count(); ++k) inside = inside && start[k].contains(p[k]);
    if (inside && CheckMembership(d, p, solver).member) members.push_back(p);
  }
  return members;
}

// Soundness over many seeded random systems of several structures: the truth and every independently found
// point of D lie in every interval.
void CheckSoundness(uint64_t first_seed, int count, const std::string& lp_solver = "clp",
                    EndpointSplit split = EndpointSplit::kDynamics, GammaRatio gamma_ratio = GammaRatio::kLargest) {
  int members_checked = 0;
  std::mt19937 rng(static_cast<unsigned>(first_seed));
  ClpSolver clp;
  for (uint64_t seed = first_seed; seed < first_seed + static_cast<uint64_t>(count); ++seed) {
    testing::RandomHwOptions opts;
    opts.min_samples = 40, opts.max_samples = 70;
    const auto inst = testing::MakeRandomHwInstance(seed, opts);
    const LiftedData d = MakeLiftedData(inst.structure, inst.data);
    const ParamBox start = BoxAround(d, inst.theta, 0.02, 0.3);
    ExactBoundsOptions options = SmallRunOptions();
    options.lp_solver = lp_solver;
    options.search.split = split;
    options.search.gamma_ratio = gamma_ratio;
    const ExactBoundsSummary s = ComputeExactBounds(options, inst.structure, inst.data, start);
    ASSERT_FALSE(s.invalidated) << inst.description;
    for (const auto& p : IndependentMembers(d, inst, start, clp, rng)) {
      ++members_checked;
      for (int k = 0; k < d.layout.count(); ++k) {
        EXPECT_LE(s.intervals[k].lower.value, p[k]) << inst.description << " " << d.layout.names[k];
        EXPECT_GE(s.intervals[k].upper.value, p[k]) << inst.description << " " << d.layout.names[k];
      }
    }
  }
  EXPECT_GT(members_checked, count);  // more than the truths alone
}

TEST(ExactSoundness, RandomSystemsSeeds1To25) { CheckSoundness(1, 25); }
TEST(ExactSoundness, RandomSystemsSeeds26To50) { CheckSoundness(26, 25); }
TEST(ExactSoundness, RandomSystemsSeeds51To75) { CheckSoundness(51, 25); }
TEST(ExactSoundness, RandomSystemsSeeds76To100) { CheckSoundness(76, 25); }
// The interior-point backend on other systems (its duals, not a simplex's, certify every prune and bound).
TEST(ExactSoundness, RandomSystemsSeeds101To125InteriorPoint) { CheckSoundness(101, 25, "ipm"); }
TEST(ExactSoundness, RandomSystemsSeeds126To150InteriorPoint) { CheckSoundness(126, 25, "ipm"); }
// The other splits (boxes cut across the endpoint's own family of parameters) and gamma ratios (each b_j in turn,
// all b_j pooled: other certificates).
TEST(ExactSoundness, RandomSystemsSeeds151To175FamilySplitPooledRatio) {
  CheckSoundness(151, 25, "clp", EndpointSplit::kFamily, GammaRatio::kPooled);
}
TEST(ExactSoundness, RandomSystemsSeeds176To200AlternateSplitRotatedRatio) {
  CheckSoundness(176, 25, "clp", EndpointSplit::kAlternate, GammaRatio::kRotate);
}
TEST(ExactSoundness, RandomSystemsSeeds201To225DynamicsGammaSplit) {
  CheckSoundness(201, 25, "clp", EndpointSplit::kDynamicsGamma);
}

TEST(ExactBounds, NarrowerThanTheStartBoxAndTheSameOnEveryExecutor) {
  const auto inst = InstanceOf(5, 80);
  const LiftedData d = MakeLiftedData(inst.structure, inst.data);
  const ParamBox start = BoxAround(d, inst.theta, 0.05, 1.0);
  ExactBoundsOptions o = SmallRunOptions();
  o.prune.max_levels = 6;
  const auto in_process = ComputeExactBounds(o, inst.structure, inst.data, start);
  o.executor = std::make_shared<sdp::ForkExecutor>(2);
  const auto forked = ComputeExactBounds(o, inst.structure, inst.data, start);
  ASSERT_EQ(in_process.intervals.size(), forked.intervals.size());
  for (std::size_t k = 0; k < forked.intervals.size(); ++k) {
    EXPECT_EQ(in_process.intervals[k].lower.value, forked.intervals[k].lower.value);
    EXPECT_EQ(in_process.intervals[k].upper.value, forked.intervals[k].upper.value);
  }
  const int a1 = d.layout.a_begin;
  EXPECT_LT(forked.intervals[a1].upper.value - forked.intervals[a1].lower.value, 0.5 * start[a1].hi - 0.5 * start[a1].lo);
  EXPECT_TRUE(forked.assumption.holds) << forked.assumption.smallest_increase;
}

TEST(ExactBounds, ARecordNoModelOfTheClassExplainsIsInvalidatedWithCertificates) {
  auto inst = InstanceOf(9, 60);
  const LiftedData d = MakeLiftedData(inst.structure, inst.data);
  // The start box excludes the truth's a_1 by far: nothing in it explains the record.
  ParamBox start = BoxAround(d, inst.theta, 0.02, 0.3);
  start[d.layout.a_begin] = Interval(inst.theta[d.layout.a_begin] + 0.5, inst.theta[d.layout.a_begin] + 0.6);
  const auto s = ComputeExactBounds(SmallRunOptions(), inst.structure, inst.data, start);
  EXPECT_TRUE(s.invalidated);
  EXPECT_FALSE(s.certificates.empty());
  for (const auto& c : s.certificates) EXPECT_GT(c.at("certificate").at("residual_lower_bound").get<double>(), 0.0);
}

#ifdef HW_CLI_PATH
TEST(ExactCli, BoundsSetExactWritesBothSetsTheAssumptionAndTheCounts) {
  testing::RandomHwOptions opts;
  opts.min_samples = 80, opts.max_samples = 80;
  testing::RandomHwInstance inst;
  for (uint64_t seed = 1;; ++seed) {  // the first instance of the example's class (na = nb = 1, poly:1 input)
    inst = testing::MakeRandomHwInstance(seed, opts);
    if (inst.structure.na == 1 && inst.structure.nb == 1 && inst.structure.strictly_proper &&
        inst.structure.input_basis.size() == 1 && inst.structure.output_basis.size() == 2)
      break;
  }
  const std::string csv = ::testing::TempDir() + "exact_cli.csv", json = ::testing::TempDir() + "exact_cli.json";
  const std::string png = ::testing::TempDir() + "exact_cli.png";
  std::remove(png.c_str());
  {
    std::ofstream out(csv);
    out << "u,y,dy\n";
    out.precision(17);
    for (std::size_t t = 0; t < inst.data.y.size(); ++t)
      out << inst.data.u[t] << "," << inst.data.y[t] << "," << inst.data.noise_bound[t] << "\n";
  }
  std::string truth;
  for (double v : inst.theta) truth += (truth.empty() ? "" : ",") + fmt::format("{:.17g}", v);
  const auto run = testing_support::RunCli(fmt::format("bounds --data {} --noise-col dy --na 1 --nb 1 --input-basis poly:1 "
                                      "--output-basis poly:2 --horizon 1 --set exact --lp-budget 4 --sweeps 1 "
                                      "--threads 1 --quiet --truth {} --json {} --plot {}",
                                      csv, truth, json, png));
  ASSERT_EQ(run.code, 0) << inst.description << "\n" << run.output;
  EXPECT_NE(run.output.find("exact set D"), std::string::npos) << run.output;
  EXPECT_NE(run.output.find("increases on the data range"), std::string::npos) << run.output;
  std::ifstream in(json);
  const nlohmann::json j = nlohmann::json::parse(in);
  EXPECT_EQ(j.at("set"), "exact");
  EXPECT_TRUE(j.at("truth_covered").get<bool>());
  EXPECT_EQ(j.at("outer_set_intervals").size(), j.at("intervals").size());
  EXPECT_TRUE(j.at("assumption").at("holds").get<bool>());
  EXPECT_GT(j.at("stage2").at("lps").get<int>(), 0);
  EXPECT_EQ(j.at("stage2").at("lp_solver"), ExactBoundsOptions{}.lp_solver);  // the default backend ran
  {  // the picture holds both sets
    std::ifstream picture(png, std::ios::binary);
    std::string magic(8, '\0');
    picture.read(magic.data(), 8);
    EXPECT_EQ(magic.substr(1, 3), "PNG");
  }
  for (const auto& iv : j.at("intervals")) {
    EXPECT_EQ(iv.at("lower").at("verification"), "verified");
    EXPECT_TRUE(iv.contains("inner")) << iv.dump();
  }
  // An unknown set is refused before any work.
  const auto bad = testing_support::RunCli(fmt::format("bounds --data {} --noise-col dy --set exactly", csv));
  EXPECT_EQ(bad.code, 2) << bad.output;
  // So are the exact stage's settings, before stage 1 runs.
  const auto zero = testing_support::RunCli(fmt::format("bounds --data {} --noise-col dy --na 1 --nb 1 --input-basis "
                                                        "poly:1 --output-basis poly:2 --horizon 1 --set exact "
                                                        "--lp-budget 0",
                                                        csv));
  EXPECT_EQ(zero.code, 2) << zero.output;
  EXPECT_NE(zero.output.find("--lp-budget 0"), std::string::npos) << zero.output;
  EXPECT_EQ(zero.output.find("orthants"), std::string::npos) << zero.output;
  const auto highs = testing_support::RunCli(fmt::format("bounds --data {} --noise-col dy --set exact --lp-solver highs", csv));
  EXPECT_EQ(highs.code, 2) << highs.output;
  EXPECT_NE(highs.output.find("--lp-solver"), std::string::npos) << highs.output;
}
#endif

}  // namespace
}  // namespace hw::exact
