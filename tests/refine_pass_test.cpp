// Endpoints resting on a solve that stopped short are solved again in a contracted box (dss/refine_pass.hpp):
// which endpoints qualify, and on a seeded instance whose solves are cut short by an iteration limit, the refined
// intervals lie inside the unrefined ones and still contain the truth. The same for every open endpoint solved
// again in the box of the full pass's own bounds (BoundsOptions::endpoint_refinements).
#include <gtest/gtest.h>

#include "core/cerone_example.hpp"
#include "dss/refine_pass.hpp"
#include "dss/set_membership.hpp"
#include "sdp/job_executor.hpp"

namespace hw::dss {
namespace {

JobOutcome Solved(double bound, bool unfinished) {
  JobOutcome r;
  r.status = "solved";
  r.bound = bound;
  r.unfinished = unfinished;
  return r;
}

// The seeded N = 60, horizon-1 instance of the paper's example in the prior box +-10.
HwOuterSet SeededHorizon1Set() {
  const auto ex = SimulateCeroneExample(3, 60, 31.0);
  HwData data{ex.u, ex.y, std::vector<double>(ex.y.size(), ex.noise_bound), "seeded"};
  return HwOuterSet(CeroneExampleStructure(), data, 1, std::vector<std::pair<double, double>>(8, {-10.0, 10.0}));
}

// Every refined interval inside the plain one, containing the truth, both endpoints verified; returns how many
// are narrower.
// Order 1 with CSDP in this process: the settings both end-to-end tests start from.
BoundsOptions Order1InProcessOptions() {
  BoundsOptions options;
  options.order = 1;
  options.solver = "csdp";
  options.executor = std::make_shared<sdp::InProcessExecutor>();
  return options;
}

int ExpectInsideWithTheTruthAndVerified(const BoundsSummary& plain, const BoundsSummary& refined) {
  const auto truth = CeroneExample::TrueParameters();
  EXPECT_EQ(plain.intervals.size(), refined.intervals.size());
  int narrower = 0;
  for (std::size_t k = 0; k < refined.intervals.size() && k < plain.intervals.size(); ++k) {
    const auto& a = plain.intervals[k];
    const auto& b = refined.intervals[k];
    EXPECT_GE(b.lower.value, a.lower.value) << b.name;
    EXPECT_LE(b.upper.value, a.upper.value) << b.name;
    EXPECT_LE(b.lower.value, truth[k] + 1e-6) << b.name;
    EXPECT_GE(b.upper.value, truth[k] - 1e-6) << b.name;
    EXPECT_EQ(b.lower.verification, "verified") << b.name;
    EXPECT_EQ(b.upper.verification, "verified") << b.name;
    narrower += (b.upper.value - b.lower.value < a.upper.value - a.lower.value - 1e-9);
  }
  return narrower;
}

TEST(RefinePass, OnlyStoppedShortBoundsThatAreTheEndpointQualify) {
  const std::vector<Objective> objectives{{0, -1}, {0, +1}, {1, -1}};
  std::vector<OrthantWork> orthants(4);
  for (int l = 0; l < 4; ++l) orthants[l].index = l;
  orthants[3].status = "empty (LP)";
  PassOutcomes full;
  // min x0: orthant 0 stopped short at -2 (the endpoint); orthant 1 stopped short at -1 (orthant 0 lies beyond).
  full[{0, 0}] = Solved(-2.0, true);
  full[{1, 0}] = Solved(-1.0, true);
  full[{2, 0}] = Solved(-1.5, false);
  full[{3, 0}] = Solved(-5.0, false);  // an empty orthant's outcome does not count
  // max x0: the endpoint 3 is a finished bound; orthant 1's stopped-short 2.5 cannot move it.
  full[{0, 1}] = Solved(3.0, false);
  full[{1, 1}] = Solved(2.5, true);
  full[{2, 1}] = Solved(1.0, false);
  full[{3, 1}] = Solved(9.0, true);  // empty orthant: never a target
  // min x1: not wanted.
  full[{0, 2}] = Solved(-7.0, true);
  full[{1, 2}] = Solved(-1.0, false);
  full[{2, 2}] = Solved(-1.0, false);
  full[{3, 2}] = Solved(-1.0, false);
  const auto targets = StoppedShortEndpoints(objectives, {0, 1}, full, orthants);
  ASSERT_EQ(targets.size(), 1u);
  EXPECT_EQ(targets[0], std::make_pair(0, 0));
  // A tie with a finished bound: the stopped-short one is still an endpoint (nothing lies beyond it).
  full[{2, 0}] = Solved(-2.0, false);
  EXPECT_EQ(StoppedShortEndpoints(objectives, {0, 1}, full, orthants).size(), 1u);
}

TEST(RefinePass, OpenEndpointsAreTheSolvedEndpointsNoWitnessReaches) {
  const std::vector<Objective> objectives{{0, -1}, {0, +1}, {1, -1}, {1, +1}};
  std::vector<OrthantWork> orthants(3);
  for (int l = 0; l < 3; ++l) orthants[l].index = l;
  orthants[2].status = "empty (LP)";
  PassOutcomes full;
  full[{0, 0}] = Solved(-2.0, false);  // min x0: the endpoint, finished, a witness at -1.5: open
  full[{1, 0}] = Solved(-1.0, true);   // orthant 0 lies beyond
  full[{0, 1}] = Solved(3.0, false);   // max x0: the endpoint, a witness reaches it: closed
  full[{1, 1}] = Solved(2.0, false);
  full[{0, 2}] = Solved(-4.0, false);  // min x1: not wanted
  full[{1, 2}] = Solved(-4.5, false);
  full[{0, 3}] = Solved(1.0, false);   // max x1: the endpoint in orthant 1, no witness: open
  full[{1, 3}] = Solved(1.5, false);
  full[{2, 3}] = Solved(9.0, false);   // empty orthant: never a target
  const std::map<int, double> witnessed{{0, -1.5}, {1, 3.0 - 1e-9}};
  const auto targets = OpenEndpoints(objectives, {0, 1, 3}, full, orthants, witnessed);
  const std::vector<std::pair<int, int>> expected{{0, 0}, {1, 3}};
  EXPECT_EQ(targets, expected);
  // Without witnesses every solved endpoint is open; a skipped outcome (settled at the box edge) never is.
  full[{0, 1}].status = "skipped";
  const std::vector<std::pair<int, int>> without{{0, 0}, {1, 3}};
  EXPECT_EQ(OpenEndpoints(objectives, {0, 1, 3}, full, orthants, {}), without);
}

TEST(RefinePass, EveryEndpointRefinedInItsOwnBoxLiesInsideAndKeepsTheTruth) {
  const HwOuterSet set = SeededHorizon1Set();
  BoundsOptions options = Order1InProcessOptions();
  const auto plain = ComputeBounds(options, set);
  options.endpoint_refinements = 1;
  const auto refined = ComputeBounds(options, set);
  EXPECT_EQ(plain.endpoint_refine_jobs, 0);
  EXPECT_GT(refined.endpoint_refine_jobs, 0) << "no open endpoint: the test proves nothing";
  EXPECT_GT(refined.endpoint_refine_tightened, 0);
  const int narrower = ExpectInsideWithTheTruthAndVerified(plain, refined);
  EXPECT_GT(narrower, 0);
  EXPECT_EQ(refined.to_json()["endpoints_refined"]["jobs"], refined.endpoint_refine_jobs);
  options.endpoint_refinements = kMaxEndpointRefinements + 1;
  std::string error;
  EXPECT_FALSE(options.IsValid(&error));
  EXPECT_NE(error.find("endpoint_refinements"), std::string::npos) << error;
  std::printf("endpoint refine jobs %d, bounds tightened %d, narrower intervals %d\n", refined.endpoint_refine_jobs,
              refined.endpoint_refine_tightened, narrower);
}

TEST(RefinePass, RefinedIntervalsLieInsideAndKeepTheTruth) {
  const HwOuterSet set = SeededHorizon1Set();
  BoundsOptions options = Order1InProcessOptions();
  options.generation.retry_undecided_rounds = false;
  options.generation.sdp.max_iterations = 12;  // every solve stops short of optimal
  options.stopped_short_refinements = 0;
  const auto plain = ComputeBounds(options, set);
  options.stopped_short_refinements = 2;
  const auto refined = ComputeBounds(options, set);
  EXPECT_EQ(plain.refine_jobs, 0);
  EXPECT_GT(refined.refine_jobs, 0) << "no endpoint stopped short: the test proves nothing";
  EXPECT_GT(refined.refine_tightened, 0);
  const int narrower = ExpectInsideWithTheTruthAndVerified(plain, refined);
  EXPECT_GT(narrower, 0);
  std::printf("refine jobs %d, bounds tightened %d, narrower intervals %d\n", refined.refine_jobs,
              refined.refine_tightened, narrower);
}

}  // namespace
}  // namespace hw::dss
