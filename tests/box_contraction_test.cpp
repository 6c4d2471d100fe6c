// Robustness and box contraction of the set-membership pipeline:
//  - a constraint-generation round that the solver fails on falls back to the last solved round's bound
//    (valid for the full set, reported not tight) instead of failing the job;
//  - the verified LP bound of one variable is a valid bound;
//  - box contraction keeps the truth inside every interval and in its orthant's contracted box, and never
//    widens an interval.
#include <algorithm>
#include <cmath>
#include <random>

#include <fmt/format.h>

#include <gtest/gtest.h>

#include "core/cerone_example.hpp"
#include "dss/basis.hpp"
#include "dss/set_membership.hpp"
#include "pop/constraint_generation.hpp"
#include "pop/moment_lp.hpp"

namespace hw::dss {
namespace {

// Solves its first `good` problems with CSDP, then reports numerical trouble (a backend giving up mid-run).
class FailsAfter : public sdp::SdpSolver {
 public:
  explicit FailsAfter(int good) : good_(good), inner_(sdp::MakeSolver("csdp")) {}
  std::string name() const override { return "fails-after"; }
  sdp::SdpSummary Solve(const sdp::SdpOptions& options, const sdp::LmiProblem& problem) override {
    if (calls_++ < good_) return inner_->Solve(options, problem);
    sdp::SdpSummary s;
    s.status = sdp::SdpStatus::kNumericalTrouble;
    s.message = "injected failure";
    s.solver = name();
    return s;
  }

 private:
  int good_, calls_ = 0;
  std::unique_ptr<sdp::SdpSolver> inner_;
};

// min x1 in [-1, 1]^2 with candidates x1 >= 0.5 (active) and x2 <= 0.9 (inactive).
pop::PolyProblem Core() {
  pop::PolyProblem p;
  p.num_vars = 2;
  p.objective = Polynomial::Variable(2, 0);
  for (int i = 0; i < 2; ++i)
    p.inequalities.push_back(Polynomial::Constant(2, 1.0) - Polynomial::Variable(2, i) * Polynomial::Variable(2, i));
  return p;
}
std::vector<Polynomial> Candidates() {
  return {Polynomial::Variable(2, 0) - Polynomial::Constant(2, 0.5),
          Polynomial::Constant(2, 0.9) - Polynomial::Variable(2, 1)};
}

TEST(ConstraintGeneration, AFailedRoundFallsBackToTheLastSolvedRound) {
  pop::ConstraintGenerationOptions o;
  o.order = 1;
  o.add_per_round = 1;
  o.linear_rows_first = false;  // candidates enter only as blocks, so that a second round is needed
  // Reference: the full run needs a second round and reaches 0.5.
  auto csdp = sdp::MakeSolver("csdp");
  const auto full = pop::SolveWithConstraintGeneration(o, Core(), Candidates(), {}, *csdp);
  ASSERT_EQ(full.status, pop::RelaxationStatus::kSolved) << full.message;
  ASSERT_GE(full.rounds, 2);
  EXPECT_NEAR(full.bound, 0.5, 1e-5);
  EXPECT_TRUE(full.tight);
  // Round 2 fails: the round-1 bound (the box, -1) is reported, valid, not tight, and verified.
  FailsAfter failing(1);
  const auto r = pop::SolveWithConstraintGeneration(o, Core(), Candidates(), {}, failing);
  ASSERT_EQ(r.status, pop::RelaxationStatus::kSolved) << r.message;
  EXPECT_FALSE(r.tight);
  EXPECT_NEAR(r.bound, -1.0, 1e-5);
  EXPECT_LE(r.bound, full.bound + 1e-9);
  EXPECT_TRUE(r.verification.verified()) << r.verification.message;
  EXPECT_EQ(r.origin, pop::BoundOrigin::kEarlierRound);
  EXPECT_EQ(r.bound_round, 1);
  EXPECT_NE(r.message.find("the bound of round 1 is reported"), std::string::npos) << r.message;
  // A failure in the first round has nothing to fall back to: the job fails.
  FailsAfter always(0);
  const auto none = pop::SolveWithConstraintGeneration(o, Core(), Candidates(), {}, always);
  EXPECT_EQ(none.status, pop::RelaxationStatus::kSolverFailed);
}

// Solves with CSDP capped at a few iterations: the solve stops short, but its last iterate X comes back.
class StopsShort : public sdp::SdpSolver {
 public:
  std::string name() const override { return "stops-short"; }
  sdp::SdpSummary Solve(const sdp::SdpOptions& options, const sdp::LmiProblem& problem) override {
    sdp::SdpOptions capped = options;
    capped.max_iterations = 4;
    return inner_->Solve(capped, problem);
  }

 private:
  std::unique_ptr<sdp::SdpSolver> inner_ = sdp::MakeSolver("csdp");
};

TEST(ConstraintGeneration, ASolveThatStopsShortStillGivesAVerifiedBound) {
  pop::ConstraintGenerationOptions o;
  o.order = 2;
  // min x1 over the disc x1^2 + x2^2 <= 0.5 in the box: -sqrt(0.5).
  pop::PolyProblem core = Core();
  const auto x1 = Polynomial::Variable(2, 0), x2 = Polynomial::Variable(2, 1);
  std::vector<Polynomial> candidates = {Polynomial::Constant(2, 0.5) - x1 * x1 - x2 * x2};
  StopsShort short_solver;
  const auto r = pop::SolveWithConstraintGeneration(o, core, candidates, {}, short_solver);
  ASSERT_NE(r.last_sdp.status, sdp::SdpStatus::kOptimal) << "the capped solve was expected to stop short";
  ASSERT_EQ(r.status, pop::RelaxationStatus::kSolved) << r.message;
  EXPECT_TRUE(r.verification.verified()) << r.verification.message;
  EXPECT_TRUE(r.bound_from_unfinished_solve);
  EXPECT_FALSE(r.tight);
  EXPECT_LE(r.bound, -std::sqrt(0.5) + 1e-9);  // a valid lower bound of the minimum
  EXPECT_TRUE(std::isfinite(r.bound));         // weak, perhaps: an unfinished iterate bounds loosely
  // Without verification, a solve that stopped short gives no bound at all.
  o.verify.enabled = false;
  EXPECT_EQ(pop::SolveWithConstraintGeneration(o, core, candidates, {}, short_solver).status, pop::RelaxationStatus::kSolverFailed);
}

// CSDP that counts its solves: the other backend of a job.
class CountingSolver : public sdp::SdpSolver {
 public:
  std::string name() const override { return "counting-csdp"; }
  sdp::SdpSummary Solve(const sdp::SdpOptions& options, const sdp::LmiProblem& problem) override {
    ++calls;
    return inner_->Solve(options, problem);
  }
  int calls = 0;

 private:
  std::unique_ptr<sdp::SdpSolver> inner_ = sdp::MakeSolver("csdp");
};

TEST(ConstraintGeneration, AnUndecidedRoundGoesToTheOtherBackendOnlyWhenAsked) {
  pop::ConstraintGenerationOptions o;
  o.order = 2;
  const auto x1 = Polynomial::Variable(2, 0), x2 = Polynomial::Variable(2, 1);
  std::vector<Polynomial> candidates = {Polynomial::Constant(2, 0.5) - x1 * x1 - x2 * x2};
  StopsShort short_solver;
  // Default: the round that stopped short keeps its verified last iterate; the other backend is not asked.
  CountingSolver other;
  const auto kept = pop::SolveWithConstraintGeneration(o, Core(), candidates, {}, short_solver, {}, &other);
  ASSERT_EQ(kept.status, pop::RelaxationStatus::kSolved) << kept.message;
  EXPECT_EQ(other.calls, 0);
  EXPECT_TRUE(kept.bound_from_unfinished_solve);
  EXPECT_LE(kept.bound, -std::sqrt(0.5) + 1e-9);
  // Asked for: the other backend solves the same LMI, and its converged round gives the bound.
  o.retry_undecided_rounds = true;
  CountingSolver retry;
  const auto retried = pop::SolveWithConstraintGeneration(o, Core(), candidates, {}, short_solver, {}, &retry);
  ASSERT_EQ(retried.status, pop::RelaxationStatus::kSolved) << retried.message;
  EXPECT_GE(retry.calls, 1);
  EXPECT_FALSE(retried.bound_from_unfinished_solve);
  EXPECT_NEAR(retried.bound, -std::sqrt(0.5), 1e-5);
  EXPECT_LE(retried.bound, -std::sqrt(0.5) + 1e-9);
}

TEST(LinearProgramBound, BoundsAVariableAndDetectsEmptiness) {
  auto solver = sdp::MakeSolver("csdp");
  // x1 >= 0.5 and x1 + x2 <= 0.2 inside [-1, 1]^2: x1 in [0.5, 1], x2 <= -0.3.
  std::vector<Polynomial> cons = {Polynomial::Variable(2, 0) - Polynomial::Constant(2, 0.5),
                                  Polynomial::Constant(2, 0.2) - Polynomial::Variable(2, 0) - Polynomial::Variable(2, 1)};
  const auto lo = pop::LinearProgramBound(cons, 2, 0, -1, {}, *solver);
  ASSERT_EQ(lo.status, pop::LinearProgramBoundResult::kBounded) << lo.summary_message;
  EXPECT_LE(lo.bound, 0.5);
  EXPECT_NEAR(lo.bound, 0.5, 1e-6);
  const auto hi = pop::LinearProgramBound(cons, 2, 1, +1, {}, *solver);
  ASSERT_EQ(hi.status, pop::LinearProgramBoundResult::kBounded) << hi.summary_message;
  EXPECT_GE(hi.bound, -0.3);
  EXPECT_NEAR(hi.bound, -0.3, 1e-6);
  cons.push_back(Polynomial::Constant(2, -0.8) - Polynomial::Variable(2, 0));  // x1 <= -0.8: empty
  EXPECT_EQ(pop::LinearProgramBound(cons, 2, 0, -1, {}, *solver).status, pop::LinearProgramBoundResult::kEmpty);
}

// A small Hammerstein-Wiener system that keeps the test fast: x = u, z_t = -a1 z_{t-1} + b1 x_{t-1},
// z = w + alpha2 w^2; parameters (alpha2, a1, b1) = (0.3, -0.5, 1.2); u uniform in [0, 1], |eta| <= 0.01.
const std::vector<double> kTruth = {0.3, -0.5, 1.2};

HwOuterSet SmallSet(int samples) {
  const HwStructure s{parse_basis("poly:1"), parse_basis("poly:2"), /*na=*/1, /*nb=*/1, /*strictly_proper=*/true};
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> unit(0.0, 1.0), noise(-0.01, 0.01);
  HwData d;
  d.source = "small";
  double z = 0.0, x_prev = 0.0;
  for (int t = 0; t < samples; ++t) {
    z = -kTruth[1] * z + kTruth[2] * x_prev;
    const double w = (-1.0 + std::sqrt(1.0 + 4.0 * kTruth[0] * z)) / (2.0 * kTruth[0]);  // z = w + 0.3 w^2, z >= 0
    const double u = unit(rng);
    d.u.push_back(u);
    d.y.push_back(w + noise(rng));
    d.noise_bound.push_back(0.01);
    x_prev = u;
  }
  return HwOuterSet(s, d, 2, std::vector<std::pair<double, double>>(3, {-5.0, 5.0}));
}

BoundsSummary RunSmall(int contraction_passes) {
  BoundsOptions options;
  options.order = 2;
  options.solver = "csdp";
  options.threads = 2;
  options.generation.retry_undecided_rounds = false;
  options.contraction_passes = contraction_passes;
  options.contraction_max_rounds = 2;
  return ComputeBounds(options, SmallSet(40));
}

TEST(BoxContraction, KeepsTheTruthAndNeverWidensAnInterval) {
  const auto plain = RunSmall(0);
  const auto contracted = RunSmall(2);
  ASSERT_EQ(plain.intervals.size(), 3u);
  ASSERT_EQ(contracted.intervals.size(), 3u);
  EXPECT_TRUE(plain.orthant_boxes.empty());
  ASSERT_FALSE(contracted.orthant_boxes.empty());
  EXPECT_GE(contracted.contraction_passes_run, 1);
  for (std::size_t k = 0; k < 3; ++k) {
    const auto& p = plain.intervals[k];
    const auto& c = contracted.intervals[k];
    SCOPED_TRACE(p.name);
    EXPECT_LE(p.lower.value, kTruth[k]);
    EXPECT_GE(p.upper.value, kTruth[k]);
    EXPECT_LE(c.lower.value, kTruth[k]);
    EXPECT_GE(c.upper.value, kTruth[k]);
    // A smaller box gives a tighter (or equal) relaxation; 1e-6 for solver accuracy.
    if (p.lower.status == "guaranteed" && c.lower.status == "guaranteed") EXPECT_GE(c.lower.value, p.lower.value - 1e-6);
    if (p.upper.status == "guaranteed" && c.upper.status == "guaranteed") EXPECT_LE(c.upper.value, p.upper.value + 1e-6);
    // The data pin every parameter well inside the prior box, so the contraction must have moved.
    EXPECT_LT(c.half_width(), 2.5);
  }
  // Every contracted box lies in the prior box, and the truth's orthant box contains the truth.
  const int truth_orthant = SmallSet(40).orthant_of(kTruth);
  bool saw_truth_orthant = false;
  for (const auto& [l, box] : contracted.orthant_boxes) {
    for (std::size_t k = 0; k < 3; ++k) {
      EXPECT_GE(box[k].first, -5.0);
      EXPECT_LE(box[k].second, 5.0);
      if (l == truth_orthant) {
        EXPECT_LE(box[k].first, kTruth[k]) << "orthant " << l << " parameter " << k;
        EXPECT_GE(box[k].second, kTruth[k]) << "orthant " << l << " parameter " << k;
      }
    }
    saw_truth_orthant = saw_truth_orthant || l == truth_orthant;
  }
  EXPECT_TRUE(saw_truth_orthant);
  for (const auto& iv : contracted.intervals)
    fmt::print("{}: plain [{:.6f}, {:.6f}], contracted [{:.6f}, {:.6f}]\n", iv.name,
               plain.intervals[&iv - &contracted.intervals[0]].lower.value,
               plain.intervals[&iv - &contracted.intervals[0]].upper.value, iv.lower.value, iv.upper.value);
}

// Before the order-3 pass every orthant's box shrinks to its order-2 bounds: the intervals keep the truth, are no
// wider than at order 2 or than order 3 in the prior box, and the truth's orthant box still holds the truth.
TEST(BoxContraction, TheFullPassRunsInTheBoxesOfTheCheapBounds) {
  BoundsOptions options;
  options.order = 3;
  options.solver = "csdp";
  options.threads = 2;
  options.generation.retry_undecided_rounds = false;
  const HwOuterSet set = SmallSet(40);
  const auto contracted = ComputeBounds(options, set);
  options.contract_before_full_pass = false;
  const auto prior_box = ComputeBounds(options, set);
  options.order = 2;
  const auto order2 = ComputeBounds(options, set);
  EXPECT_TRUE(prior_box.orthant_boxes.empty());
  ASSERT_FALSE(contracted.orthant_boxes.empty());
  const int truth_orthant = set.orthant_of(kTruth);
  for (const auto& [l, box] : contracted.orthant_boxes)
    if (l == truth_orthant)
      for (std::size_t k = 0; k < 3; ++k) {
        EXPECT_LE(box[k].first, kTruth[k]);
        EXPECT_GE(box[k].second, kTruth[k]);
        EXPECT_LT(box[k].second - box[k].first, 5.0) << "parameter " << k << ": the cheap bounds must contract";
      }
  for (std::size_t k = 0; k < 3; ++k) {
    const auto& c = contracted.intervals[k];
    SCOPED_TRACE(c.name);
    EXPECT_EQ(c.lower.status, "guaranteed");
    EXPECT_EQ(c.upper.status, "guaranteed");
    EXPECT_LE(c.lower.value, kTruth[k]);
    EXPECT_GE(c.upper.value, kTruth[k]);
    for (const auto* other : {&prior_box.intervals[k], &order2.intervals[k]}) {
      EXPECT_GE(c.lower.value, other->lower.value - 1e-6);
      EXPECT_LE(c.upper.value, other->upper.value + 1e-6);
    }
  }
}

}  // namespace
}  // namespace hw::dss
