// Jobs that end once their bound passes a value a certified feasible point attains (ConstraintGenerationOptions::
// stop_beyond, dss/edge_witness.hpp WitnessedExtremes), and jobs not run because the orthant's sign constraints
// already bound them beyond such a value: the bound they report stays valid, the value only comes from points
// that are certified, and a run with the stops gives the endpoints of a run without them.
#include <algorithm>
#include <cmath>

#include <gtest/gtest.h>

#include "core/cerone_example.hpp"
#include "dss/relax_job.hpp"
#include "dss/edge_witness.hpp"
#include "dss/set_membership.hpp"
#include "pop/constraint_generation.hpp"
#include "seeded_example.hpp"

namespace hw::dss {
namespace {

// min / max of parameter k over orthant l by constraint generation over every data row, at order 2.
pop::ConstraintGenerationResult Solve(const HwOuterSet& set, int l, int k, bool maximize, double stop_beyond) {
  const pop::PolyProblem core = OrthantObjectiveCore(set, l, {k, maximize ? +1 : -1});
  std::vector<Polynomial> candidates;
  for (const auto& d : set.data_constraints(l)) candidates.push_back(d.g);
  pop::ConstraintGenerationOptions o;
  o.order = 2;
  o.stop_beyond = stop_beyond;
  o.sdp.acceptable_gap = 1e-5;
  o.sdp.infeasibility_tolerance = 0.5;
  auto solver = sdp::MakeSolver("csdp");
  return pop::SolveWithConstraintGeneration(o, core, candidates, {}, *solver);
}

TEST(WitnessStop, AJobEndsOnceItsVerifiedBoundPassesTheValueAndTheBoundStaysValid) {
  const HwOuterSet set = SeededSet(3, 30, 1, 31.0);
  const auto truth = CeroneExample::TrueParameters();
  const int l = set.orthant_of(truth);
  const int a1 = 4;
  for (const bool maximize : {false, true}) {
    const double dir = maximize ? -1.0 : 1.0;  // +1: a lower bound (min)
    const auto full = Solve(set, l, a1, maximize, NAN);
    ASSERT_EQ(full.status, pop::RelaxationStatus::kSolved);
    ASSERT_GT(full.rounds, 1) << "the instance no longer needs several rounds";
    EXPECT_FALSE(full.beyond_known_value);
    // A value far inside the relaxation's bound (below it for min): an early round's bound passes it.
    const double inside = full.bound - dir * 0.5;
    const auto early = Solve(set, l, a1, maximize, inside);
    ASSERT_EQ(early.status, pop::RelaxationStatus::kSolved);
    EXPECT_TRUE(early.beyond_known_value);
    EXPECT_LT(early.rounds, full.rounds);
    EXPECT_GE(dir * early.bound, dir * inside);
    // Still a bound of the full relaxation (a subset of its inequalities): never past the converged one.
    EXPECT_LE(dir * early.bound, dir * full.bound + 1e-7);
    EXPECT_TRUE(early.verification.verified());
    // A value the relaxation never reaches: the job runs to convergence, same bound.
    const auto unreached = Solve(set, l, a1, maximize, full.bound + dir * 0.5);
    EXPECT_FALSE(unreached.beyond_known_value);
    EXPECT_EQ(unreached.rounds, full.rounds);
    EXPECT_DOUBLE_EQ(unreached.bound, full.bound);
  }
}

TEST(WitnessStop, OnlyCertifiedPointsInsideTheirOrthantsBoxGiveValues) {
  const HwOuterSet set = SeededSet(5, 60, 2, 31.0);
  const auto truth = CeroneExample::TrueParameters();
  const int l = set.orthant_of(truth);
  std::vector<Objective> objectives;
  for (int k = 0; k < set.num_vars(); ++k) objectives.push_back({k, -1}), objectives.push_back({k, +1});
  OrthantWork w;
  w.index = l;
  w.box = set.box();
  auto far = truth;
  far[4] = 9.0;  // a1 far from every point that explains the data: not certified
  const auto certified = CertifiedFeasiblePoints(set, {w}, {{{l, 0}, truth}, {{l, 1}, far}});
  ASSERT_EQ(certified.size(), 1u);
  EXPECT_EQ(certified[0].orthant, l);
  EXPECT_GE(certified[0].certified_min_slack, 0.0);
  const auto extremes = WitnessedExtremes(objectives, certified);
  ASSERT_EQ(extremes.size(), objectives.size());
  for (std::size_t j = 0; j < objectives.size(); ++j) EXPECT_EQ(extremes.at(j), truth[objectives[j].param]);
  // A box that leaves the truth out (a contracted box of the orthant): its point says nothing there.
  w.box[4] = {0.0, 1.0};
  EXPECT_TRUE(CertifiedFeasiblePoints(set, {w}, {{{l, 0}, truth}}).empty());
  // A point claimed for another orthant is checked against that orthant's inequalities.
  OrthantWork other = w;
  other.index = l ^ 1;
  other.box = set.box();
  EXPECT_TRUE(CertifiedFeasiblePoints(set, {other}, {{{l ^ 1, 0}, truth}}).empty());
}

TEST(WitnessStop, TheReportedFeasiblePointsAreTheMostExtremeOnesEachOnce) {
  const int dim = 3;
  auto point = [&](double x0, double x1, double x2) { return FeasiblePoint{0, {x0, x1, x2}, 0.0}; };
  const std::vector<FeasiblePoint> points = {point(0, 0, 0), point(-2, 5, 1), point(3, 5, -1), point(1, -4, 1)};
  std::vector<Objective> objectives;
  for (int k = 0; k < dim; ++k) objectives.push_back({k, -1}), objectives.push_back({k, +1});
  const auto extremes = WitnessedExtremes(objectives, points);
  EXPECT_EQ(extremes.at(0), -2);
  EXPECT_EQ(extremes.at(1), 3);
  EXPECT_EQ(extremes.at(2), -4);
  EXPECT_EQ(extremes.at(3), 5);
  EXPECT_EQ(extremes.at(4), -1);
  EXPECT_EQ(extremes.at(5), 1);
  // x1's max is attained twice (points 1 and 2): the first is reported; x2's max by points 1 and 3: point 1.
  const auto extreme = ExtremeFeasiblePoints(objectives, points);
  ASSERT_EQ(extreme.size(), 3u);
  EXPECT_EQ(extreme[0].point, points[1].point);
  EXPECT_EQ(extreme[1].point, points[2].point);
  EXPECT_EQ(extreme[2].point, points[3].point);
  EXPECT_TRUE(ExtremeFeasiblePoints(objectives, {}).empty());
}

TEST(WitnessStop, AnOrthantWhoseSignBoundIsBeyondAWitnessedValueIsSettledWithoutAnSdp) {
  const HwOuterSet set = SeededSet(7, 40, 1, 31.0);
  const auto truth = CeroneExample::TrueParameters();
  const auto& names = set.layout().names;
  const int alpha2 = static_cast<int>(std::find(names.begin(), names.end(), "alpha2") - names.begin());
  const int a1 = static_cast<int>(std::find(names.begin(), names.end(), "a1") - names.begin());
  const int b1 = static_cast<int>(std::find(names.begin(), names.end(), "b1") - names.begin());
  const auto& q = set.sign_names();
  const int alpha2_bit = static_cast<int>(std::find(q.begin(), q.end(), "alpha2") - q.begin());
  ASSERT_LT(alpha2_bit, static_cast<int>(q.size()));
  OrthantWork w;  // the truth's orthant: alpha2 >= 0, and Q1_1 = -a1 <= 0, so a1 >= 0
  w.index = set.orthant_of(truth);
  w.box = set.box();
  const auto settled = SettleBySignBeyondWitness(set, w, {alpha2, -1}, -1.0);
  ASSERT_TRUE(settled.has_value());
  EXPECT_EQ(settled->status, JobStatus::kSkipped);
  EXPECT_EQ(settled->origin, JobOrigin::kSignConstraint);
  EXPECT_EQ(settled->bound, 0.0);
  EXPECT_EQ(settled->verification, sdp::VerifyStatus::kVerified);
  EXPECT_EQ(SettleBySignBeyondWitness(set, w, {alpha2, -1}, 0.0)->bound, 0.0);  // at the value: cannot move it
  EXPECT_FALSE(SettleBySignBeyondWitness(set, w, {alpha2, -1}, 0.3));  // the orthant may hold alpha2 < 0.3
  EXPECT_FALSE(SettleBySignBeyondWitness(set, w, {alpha2, -1}, NAN));
  EXPECT_FALSE(SettleBySignBeyondWitness(set, w, {alpha2, +1}, 5.0));  // the sign bounds only one side
  EXPECT_EQ(SettleBySignBeyondWitness(set, w, {a1, -1}, -0.5)->bound, 0.0);  // a sign polynomial -a1
  EXPECT_FALSE(SettleBySignBeyondWitness(set, w, {b1, -1}, -3.0));  // no sign polynomial: the box edge -10
  EXPECT_EQ(SettleBySignBeyondWitness(set, w, {b1, -1}, -10.0)->bound, -10.0);
  OrthantWork negative = w;  // alpha2 <= 0
  negative.index = w.index ^ (1 << alpha2_bit);
  EXPECT_EQ(SettleBySignBeyondWitness(set, negative, {alpha2, +1}, 0.8)->bound, 0.0);
  EXPECT_FALSE(SettleBySignBeyondWitness(set, negative, {alpha2, -1}, -1.0));
}

TEST(WitnessStop, TheEngineGivesTheEndpointsOfARunWithoutStops) {
  // Horizon 1, order 2: small jobs. The seed of each orthant (min alpha2) never stops, so the stops change no
  // path but the stopped jobs' own: the endpoints are the same numbers.
  const HwOuterSet set = SeededSet(7, 40, 1, 31.0);
  BoundsOptions options;
  options.order = 2;
  options.threads = 2;
  options.solver = "csdp";
  options.parameters = {"alpha2", "b1"};
  const BoundsSummary with = ComputeBounds(options, set);
  options.edge_witness.stop_beyond_witnesses = false;
  const BoundsSummary without = ComputeBounds(options, set);
  ASSERT_GT(with.jobs_stopped_beyond_witness + with.jobs_settled_by_sign, 0)
      << "the instance no longer exercises the stops";
  EXPECT_EQ(without.jobs_stopped_beyond_witness + without.jobs_settled_by_sign, 0);
  EXPECT_LT(with.sdp_solves, without.sdp_solves);
  CompareEndpoints(with, without, [](const std::string& name, std::size_t, const Endpoint& x, const Endpoint& y, bool) {
    EXPECT_NEAR(x.value, y.value, 1e-9 * (1 + std::abs(y.value))) << name;
  });
}

}  // namespace
}  // namespace hw::dss
