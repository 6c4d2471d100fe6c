// The interior-point LP backend (exact/ipm_solver.hpp) and its simplex fallback (exact/fallback_solver.hpp):
// optima against CLP, every special row and column kind, infeasibility, the objective cutoff, and duals that
// certify what CLP's certify.
#include <cmath>

#include <gtest/gtest.h>

#include "exact/box_evaluation.hpp"
#include "exact/clp_solver.hpp"
#include "exact/exact_bounds.hpp"
#include "exact/ipm_solver.hpp"
#include "exact/safe_bound.hpp"
#include "random_hw.hpp"
#include "small_lps.hpp"

namespace hw::exact {
namespace {

constexpr double kInf = INFINITY;

TEST(IpmSolver, SolvesASmallLpAndItsDualsCertifyTheOptimum) {
  const LpProblem lp = testing_lps::TwoRowLp();  // optimum 1.4 at (0.8, 0.6)
  const int x = 0, y = 1;
  IpmSolver ipm;
  const LpResult r = ipm.Solve(lp, {}, {});
  ASSERT_EQ(r.status, LpStatus::kOptimal) << r.message;
  EXPECT_NEAR(r.objective, 1.4, 1e-8);
  EXPECT_NEAR(r.primal[x], 0.8, 1e-6);
  EXPECT_NEAR(r.primal[y], 0.6, 1e-6);
  const double safe = SafeLowerBound(lp, r.duals);
  EXPECT_LE(safe, 1.4 + 1e-15);
  EXPECT_GT(safe, 1.4 - 1e-8);
  EXPECT_TRUE(r.basis.empty());  // no basis: nothing to warm-start from
}

TEST(IpmSolver, HandlesEqualityRowsFixedColumnsAndFreeRows) {
  // min x - y  s.t.  x + y - f = 1 (f fixed at 0.5), x - y free row, 0 <= x, y <= 4: x + y = 1.5, optimum -1.5.
  LpProblem lp;
  const int x = lp.AddColumn(0, 4), y = lp.AddColumn(0, 4), f = lp.AddColumn(0.5, 0.5);
  lp.obj = {1.0, -1.0, 0.0};
  const int eq = lp.AddRow(1, 1), free = lp.AddRow(-kInf, kInf);
  lp.AddEntry(eq, x, 1), lp.AddEntry(eq, y, 1), lp.AddEntry(eq, f, -1);
  lp.AddEntry(free, x, 1), lp.AddEntry(free, y, -1);
  IpmSolver ipm;
  const LpResult r = ipm.Solve(lp, {}, {});
  ASSERT_EQ(r.status, LpStatus::kOptimal) << r.message;
  EXPECT_NEAR(r.objective, -1.5, 1e-8);
  EXPECT_EQ(r.primal[f], 0.5);
  EXPECT_EQ(r.duals[free], 0.0);
  EXPECT_GT(SafeLowerBound(lp, r.duals), -1.5 - 1e-8);
  EXPECT_LE(SafeLowerBound(lp, r.duals), -1.5 + 1e-12);
}

TEST(IpmSolver, AnInfeasibleLpEndsAtTheCutoffWithDualsThatProveIt) {
  // x >= 2 and x <= 1 as rows over 0 <= x <= 10; min 0: the dual bound grows without limit.
  LpProblem lp;
  const int x = lp.AddColumn(0, 10);
  lp.obj = {0.0};
  const int r1 = lp.AddRow(2, kInf), r2 = lp.AddRow(-kInf, 1);
  lp.AddEntry(r1, x, 1), lp.AddEntry(r2, x, 1);
  IpmSolver ipm;
  LpSolveOptions options;
  options.objective_cutoff = 0.0;
  const LpResult cut = ipm.Solve(lp, {}, options);
  EXPECT_EQ(cut.status, LpStatus::kCutoff) << cut.message;
  EXPECT_GT(SafeLowerBound(lp, cut.duals), 0.0);  // no point has objective <= 0: there is no point
  const LpResult plain = ipm.Solve(lp, {}, {});
  EXPECT_EQ(plain.status, LpStatus::kInfeasible) << plain.message;
  EXPECT_GT(SafeLowerBound(lp, plain.duals), 0.0);
}

// Lifted LPs of random systems, both forms: the interior point's optimum and certificate against CLP's.
TEST(IpmSolver, AgreesWithClpOnLiftedLpsOfRandomSystems) {
  ClpSolver clp;
  IpmSolver ipm;
  auto with_fallback = MakeLpSolver("ipm");
  int optimal = 0, total = 0;
  for (uint64_t seed = 1; seed <= 12; ++seed) {
    testing::RandomHwOptions opts;
    opts.min_samples = 60, opts.max_samples = 120;
    const auto inst = testing::MakeRandomHwInstance(seed, opts);
    const LiftedData d = MakeLiftedData(inst.structure, inst.data);
    ParamBox box;
    for (int k = 0; k < d.layout.count(); ++k) {
      const bool is_a = k >= d.layout.a_begin && k < d.layout.a_begin + d.structure.na;
      const double w = is_a ? 0.01 : 0.5;
      box.emplace_back(inst.theta[k] - w, inst.theta[k] + w);
    }
    for (int k = 0; k < d.layout.count(); ++k) {
      LiftedLp lifted = BuildLiftedLp(d, box, WholeRecord(d), LiftedForm::kBounding);
      std::vector<double> weights(d.layout.count(), 0.0);
      weights[k] = k % 2 ? -1.0 : 1.0;
      lifted.SetParameterObjective(weights);
      const LpResult rc = clp.Solve(lifted.lp, {}, {});
      ASSERT_EQ(rc.status, LpStatus::kOptimal) << inst.description;
      const double scale = 1.0 + std::abs(rc.objective);
      // Validity: any dual certifies, so the interior point's bound never passes the optimum.
      const LpResult ri = ipm.Solve(lifted.lp, {}, {});
      EXPECT_LE(SafeLowerBound(lifted.lp, ri.duals), rc.objective + 1e-9 * scale) << inst.description;
      ++total;
      if (ri.status == LpStatus::kOptimal) {
        ++optimal;
        EXPECT_NEAR(ri.objective, rc.objective, 1e-6 * scale) << inst.description;
        EXPECT_GT(SafeLowerBound(lifted.lp, ri.duals), rc.objective - 1e-6 * scale) << inst.description;
      }
      // With the fallback every LP ends optimal, as tight as CLP's.
      const LpResult rf = with_fallback->Solve(lifted.lp, {}, {});
      ASSERT_EQ(rf.status, LpStatus::kOptimal) << rf.message;
      EXPECT_GT(SafeLowerBound(lifted.lp, rf.duals), rc.objective - 1e-6 * scale) << inst.description;
      // The truth is in the box, so no bound passes it.
      EXPECT_LE(SafeLowerBound(lifted.lp, rf.duals), weights[k] * inst.theta[k] + 1e-12) << inst.description;
    }
  }
  // Most LPs need no fallback (a backend that always fell back would be CLP with extra steps).
  EXPECT_GT(optimal, total * 3 / 4) << optimal << " of " << total;
}

TEST(IpmSolver, PrunesAFarBoxAndKeepsTheTruthsBox) {
  testing::RandomHwOptions opts;
  opts.min_samples = opts.max_samples = 80;
  const auto inst = testing::MakeRandomHwInstance(11, opts);
  const LiftedData d = MakeLiftedData(inst.structure, inst.data);
  ParamBox box;
  for (int k = 0; k < d.layout.count(); ++k) box.emplace_back(inst.theta[k] - 0.01, inst.theta[k] + 0.01);
  auto solver = MakeLpSolver("ipm");
  BoxEvaluationOptions ev;
  ev.cheap_window = 0;
  EXPECT_EQ(TestBoxEmpty(d, box, ev, *solver).verdict, BoxVerdict::kKept);
  ParamBox far = box;
  far[d.layout.a_begin].lo += 0.3, far[d.layout.a_begin].hi += 0.3;
  const BoxEvaluation e = TestBoxEmpty(d, far, ev, *solver);
  ASSERT_EQ(e.verdict, BoxVerdict::kPruned);
  EXPECT_GT(e.certificate->residual_lower_bound, 0.0);
}

}  // namespace
}  // namespace hw::exact
