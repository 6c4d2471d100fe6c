// Exact row reduction (dss/row_reduction.hpp): dropped rows are implied, and on random small
// Hammerstein-Wiener instances the relaxation over the kept rows gives the same bound as over every row
// (same solver, every row as its full localizing block).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>

#include <gtest/gtest.h>

#include "compare/methods.hpp"
#include "compare/scenario.hpp"
#include "dss/basis.hpp"
#include "dss/engine_setup.hpp"
#include "dss/hw_outer_set.hpp"
#include "dss/job_function.hpp"
#include "dss/row_reduction.hpp"
#include "dss/set_membership.hpp"
#include "pop/constraint_generation.hpp"

namespace hw::dss {
namespace {

Polynomial X(int i) { return Polynomial::Variable(2, i); }
Polynomial C(double c) { return Polynomial::Constant(2, c); }

TEST(RowReduction, DropsExactlyTheRowsThatAreNonnegativeCombinations) {
  // Step-1 rows in two variables: r0 = x1 - 0.1, r1 = x2 - 0.1, r2 = r0 + 2 r1 + 0.5 (implied), r3 = -x1 + 0.9
  // (not implied by the others), r4 = 3 r3 (implied).
  const std::vector<Polynomial> rows = {X(0) - C(0.1), X(1) - C(0.1), X(0) + X(1) * 2.0 + C(0.2), C(0.9) - X(0),
                                        (C(0.9) - X(0)) * 3.0};
  const std::vector<int> steps(rows.size(), 1);
  const auto r = ReduceDataRows({}, rows, steps, {});
  // Rows are tested in index order against the rows still kept: r2 = r0 + 2 r1 + 0.5 goes, r3 = r4 / 3 goes,
  // and r4 stays (nothing left gives -x1).
  EXPECT_EQ(r.kept.size(), 3u);
  for (int k : r.kept) EXPECT_NE(k, 2);
  ASSERT_EQ(r.per_step.size(), 1u);
  EXPECT_EQ(r.per_step[0].rows, 5);
  EXPECT_EQ(r.per_step[0].kept, 3);
  // Fixed constraints count as generators: with x1 - 0.1 >= 0 fixed, r0 itself is implied.
  const auto with_fixed = ReduceDataRows({}, rows, steps, {X(0) - C(0.1)});
  EXPECT_EQ(with_fixed.kept.size(), 2u);
  // Off: everything kept.
  RowReductionOptions off;
  off.enabled = false;
  EXPECT_EQ(ReduceDataRows(off, rows, steps, {}).kept.size(), rows.size());
}

TEST(RowReduction, RowsOfAHigherLocalizingOrderAreNeverUsedForALowerOne) {
  // A degree-2 row (localizing order delta - 1) may combine fixed constraints of degree <= 2 only: a degree-3
  // one has a smaller localizing matrix, which cannot contain the row's.
  const Polynomial cubic = X(0) * X(0) * X(1);
  const auto low = ReduceDataRows({}, {X(0) * X(0) + C(0.5)}, {1}, {X(0) * X(0) - C(0.1)});
  EXPECT_TRUE(low.kept.empty());  // x1^2 + 0.5 = (x1^2 - 0.1) + 0.6
  const auto high = ReduceDataRows({}, {cubic + X(0) * X(0) + C(0.5)}, {1}, {cubic, X(0) * X(0) - C(0.1)});
  EXPECT_TRUE(high.kept.empty());  // the row itself has degree 3: the cubic constraint is usable
  const auto mixed = ReduceDataRows({}, {X(0) * X(0) + C(0.5), cubic + C(0.5)}, {1, 1}, {cubic});
  // The degree-2 row has no degree-2 generator but the constant; the cubic row = cubic + 0.5 is implied.
  EXPECT_EQ(mixed.kept, std::vector<int>{0});
}

TEST(RowReduction, ARowWhoseLpHitsTheIterationLimitIsKeptAndCounted) {
  // r2 = r0 + 2 r1 + 0.2 needs at least one simplex pivot from the standard basis; with a limit of one iteration
  // per attempt its LP stops short, so the row stays (always valid), and the count says why.
  const std::vector<Polynomial> rows = {X(0) - C(0.1), X(1) - C(0.1), X(0) + X(1) * 2.0 + C(0.2)};
  const std::vector<int> steps(rows.size(), 1);
  RowReductionOptions limited;
  limited.simplex_iteration_limit = 1;
  const auto r = ReduceDataRows(limited, rows, steps, {});
  ASSERT_EQ(r.per_step.size(), 1u);
  EXPECT_EQ(r.kept.size(), 3u);
  EXPECT_GE(r.per_step[0].iteration_limited, 1);
  const auto free = ReduceDataRows({}, rows, steps, {});
  EXPECT_EQ(free.kept.size(), 2u);
  EXPECT_EQ(free.per_step[0].iteration_limited, 0);
  limited.simplex_iteration_limit = 0;
  std::string error;
  EXPECT_FALSE(limited.IsValid(&error));
}

TEST(RowReduction, AnLpThatCyclesFromTheWarmBasisIsSolvedFromTheStandardOne) {
  // Run 7 of `compare --scenario setmembership-example --seed 1` (record seed 8): in orthant 50, one step-2 LP
  // cycled from the previous row's basis (GLPK's primal simplex, millions of iterations at zero objective and
  // constant infeasibility), and the study's run never finished. With the iteration limit it is solved again from
  // the standard basis and the reduction ends with the same kind of result as every other orthant.
  const auto scenario = compare::LoadScenario("setmembership-example");
  double bound = 0.0;
  const auto rec = compare::RandomInputRecord(scenario.plant, scenario.input_lo, scenario.input_hi, 300, 31.0, 0.0,
                                              8, &bound);
  const auto cls = compare::SetMembershipTruth(scenario.plant);
  const HwData data{rec.u, rec.y, std::vector<double>(rec.y.size(), bound), "compare run 7"};
  const HwOuterSet set(cls.structure, data, 2, std::vector<std::pair<double, double>>(cls.names.size(), {-10, 10}));
  const int orthant = 50;
  std::vector<Polynomial> rows;
  std::vector<int> steps;
  for (const auto& d : set.data_constraints(orthant))
    if (d.s == 2) {
      rows.push_back(d.g);
      steps.push_back(d.s);
    }
  std::vector<Polynomial> fixed = set.box_constraints();
  for (auto& g : set.sign_constraints(orthant)) fixed.push_back(g);
  const auto r = ReduceDataRows({}, rows, steps, fixed);
  EXPECT_GE(r.restarts_after_limit, 1);
  ASSERT_EQ(r.per_step.size(), 1u);
  EXPECT_EQ(r.per_step[0].iteration_limited, 0);
  EXPECT_EQ(r.per_step[0].rows, 594);
  EXPECT_LT(r.per_step[0].kept, 300);  // measured 203, as the neighbouring orthants' 175-292
}

// A random Hammerstein–Wiener instance: x = u + gamma2 u^2, z_t = -a1 z_{t-1} + b1 x_{t-1}, z = w + alpha2 w^2.
std::pair<HwOuterSet, std::vector<double>> RandomSet(unsigned seed, int samples, int horizon) {
  const HwStructure s{parse_basis("poly:2"), parse_basis("poly:2"), /*na=*/1, /*nb=*/1, /*strictly_proper=*/true};
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  const double gamma2 = 0.2 + 0.3 * std::abs(unit(rng)), alpha2 = 0.1 + 0.2 * std::abs(unit(rng));
  const double a1 = -0.6 * unit(rng), b1 = 1.0 + 0.5 * unit(rng), noise = 0.1;
  HwData d;
  double z = 0.0, x_prev = 0.0;
  for (int t = 0; t < samples; ++t) {
    z = -a1 * z + b1 * x_prev;
    const double disc = std::max(0.0, 1.0 + 4.0 * alpha2 * z);
    const double w = (-1.0 + std::sqrt(disc)) / (2.0 * alpha2);
    const double u = unit(rng);
    d.u.push_back(u);
    d.y.push_back(w + noise * unit(rng));
    d.noise_bound.push_back(noise);
    x_prev = u + gamma2 * u * u;
  }
  return {HwOuterSet(s, d, horizon, std::vector<std::pair<double, double>>(4, {-3.0, 3.0})), {gamma2, alpha2, a1, b1}};
}

// min / max of parameter k over orthant l with `rows` as full blocks; `checked` rows are left out of the LMI but
// checked at its optimal moments (max_violation: the largest relative violation of their localizing matrices).
pop::ConstraintGenerationResult DenseBound(const HwOuterSet& set, int l, const std::vector<int>& rows,
                                      const std::vector<int>& checked, int k, bool maximize) {
  pop::PolyProblem core = OrthantObjectiveCore(set, l, {k, maximize ? +1 : -1});
  const auto all = set.data_constraints(l);
  for (int i : rows) core.inequalities.push_back(all[i].g);
  std::vector<Polynomial> candidates;
  for (int i : checked) candidates.push_back(all[i].g);
  pop::ConstraintGenerationOptions o;
  o.order = 2;
  o.max_rounds = 1;
  o.linear_rows_first = false;
  o.verify.enabled = false;
  o.sdp.gap_tolerance = 1e-9;
  auto solver = sdp::MakeSolver("sdpa");
  const auto r = pop::SolveWithConstraintGeneration(o, core, candidates, {}, *solver);
  EXPECT_EQ(r.status, pop::RelaxationStatus::kSolved) << r.message;
  return r;
}

TEST(RowReduction, ReducedAndUnreducedRelaxationsGiveTheSameBound) {
  int dropped_total = 0;
  double worst_difference = 0.0;
  for (unsigned seed : {1u, 2u, 3u}) {
    const auto [set, truth] = RandomSet(seed, 25, 2);
    const int l = set.orthant_of(truth);  // the orthant of the true parameters (the data cannot empty it)
    const auto data = set.data_constraints(l);
    std::vector<Polynomial> rows;
    std::vector<int> steps, every;
    for (std::size_t i = 0; i < data.size(); ++i) {
      rows.push_back(data[i].g);
      steps.push_back(data[i].s);
      every.push_back(static_cast<int>(i));
    }
    std::vector<Polynomial> fixed = set.box_constraints();
    for (auto& g : set.sign_constraints(l)) fixed.push_back(g);
    const auto red = ReduceDataRows({}, rows, steps, fixed);
    std::vector<int> dropped;
    for (int i : every)
      if (!std::binary_search(red.kept.begin(), red.kept.end(), i)) dropped.push_back(i);
    dropped_total += static_cast<int>(dropped.size());
    for (int k : {0, 2}) {
      for (bool maximize : {false, true}) {
        const auto full = DenseBound(set, l, every, {}, k, maximize);
        const auto reduced = DenseBound(set, l, red.kept, dropped, k, maximize);
        const std::string what = "seed " + std::to_string(seed) + " parameter " + std::to_string(k) +
                                 (maximize ? " max" : " min");
        // Exactness: the reduced relaxation's optimal moments satisfy every dropped row's localizing matrix, so
        // they are feasible for the full relaxation and both optima coincide.
        EXPECT_LE(reduced.max_violation, 1e-7) << what;
        // The bounds then agree up to the solves' accuracy: on these thin sets SDPA's dense solve (every
        // near-redundant row in the LMI) is off by up to 2e-5 (measured: its max of alpha2 on seed 3 lies 2e-5
        // BELOW the reduced one, which the exactness check above shows to be feasible for it).
        EXPECT_NEAR(reduced.bound, full.bound, 5e-5 * std::max(1.0, std::abs(full.bound))) << what;
        worst_difference = std::max(worst_difference, std::abs(reduced.bound - full.bound));
      }
    }
  }
  EXPECT_GT(dropped_total, 0) << "the instances should have implied rows, or the test proves nothing";
  RecordProperty("worst_bound_difference", std::to_string(worst_difference));
  std::printf("rows dropped: %d; worst |reduced - full| bound difference: %.3g\n", dropped_total, worst_difference);
}

TEST(RowReduction, OneJobPerHorizonStepKeepsTheRowsOfOneJobPerOrthant) {
  // Rows of different steps never combine, so the engine's per-step reduce jobs keep exactly the rows that one
  // job over every row keeps (and their counts per step match).
  const auto [set, truth] = RandomSet(4, 40, 3);
  const int l = set.orthant_of(truth);
  const auto job = MakeJobFunction(ToEngineSettings(BoundsOptions{}), set);
  auto reduce = [&](int step) {
    nlohmann::json spec{{"kind", "reduce"}, {"l", l}, {"box", set.box()}};
    if (step != 0) spec["step"] = step;
    return nlohmann::json::parse(job(spec.dump()));
  };
  const auto whole = reduce(0);
  std::vector<int> union_of_steps;
  nlohmann::json counts = nlohmann::json::array();
  for (int s = 1; s <= set.horizon(); ++s) {
    const auto part = reduce(s);
    ASSERT_EQ(part.at("per_step").size(), 1u);
    EXPECT_EQ(part.at("per_step")[0].at("step"), s);
    counts.push_back(part.at("per_step")[0]);
    for (int r : part.at("kept")) union_of_steps.push_back(r);
  }
  std::sort(union_of_steps.begin(), union_of_steps.end());
  EXPECT_EQ(union_of_steps, whole.at("kept").get<std::vector<int>>());
  EXPECT_EQ(counts, whole.at("per_step"));
  EXPECT_LT(union_of_steps.size(), set.data_constraints(l).size()) << "some rows should be implied";
}

}  // namespace
}  // namespace hw::dss
