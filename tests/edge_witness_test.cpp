// Endpoints settled by feasible points at the prior box edge (dss/edge_witness.hpp): the certified slack
// accepts points of D^ss(n) and rejects points outside, and a run with the stage gives the endpoints of a run
// without it (every endpoint by SDP).
#include <algorithm>
#include <cmath>

#include <gtest/gtest.h>

#include "core/cerone_example.hpp"
#include "dss/edge_witness.hpp"
#include "dss/set_membership.hpp"
#include "seeded_example.hpp"

namespace hw::dss {
namespace {

TEST(EdgeWitness, CertifiedSlackAcceptsTheTruthAndRejectsAPointOutside) {
  const HwOuterSet set = SeededSet(5, 60, 2, 31.0, 10.0);
  const auto truth = CeroneExample::TrueParameters();
  const int l = set.orthant_of(truth);
  EXPECT_GE(CertifiedMinSlack(set, l, truth), 0.0);
  // The allowance only lowers the slack: never above the plain evaluation.
  EXPECT_LE(CertifiedMinSlack(set, l, truth), set.min_slack(truth));
  auto far = truth;
  far[4] = 9.0;  // a1 far from any point that explains the data
  EXPECT_LT(CertifiedMinSlack(set, set.orthant_of(far), far), 0.0);
  // A point is checked against the orthant it is claimed for: the truth's sign pattern flipped is outside.
  EXPECT_LT(CertifiedMinSlack(set, l ^ 1, truth), 0.0);
}

TEST(EdgeWitness, SettledEndpointsEqualTheRelaxationsAndContainTheTruth) {
  // n = 2 at 31 dB: D^ss(2) reaches the prior box in gamma2 and alpha3 (the scaling ray of the example), so the
  // stage settles endpoints; the run without it solves them by SDP.
  const HwOuterSet set = SeededSet(5, 60, 2, 31.0, 10.0);
  BoundsOptions options;
  options.order = 2;
  options.threads = 2;
  options.generation.retry_undecided_rounds = false;
  options.parameters = {"gamma2", "alpha3"};
  options.moment_witnesses = false;  // the feasible points below are this stage's alone
  const BoundsSummary with = ComputeBounds(options, set);
  options.edge_witness.enabled = false;
  const BoundsSummary without = ComputeBounds(options, set);
  ASSERT_GT(with.edge_witness_settled, 0) << "the instance no longer exercises the stage";
  EXPECT_LT(with.sdp_jobs, without.sdp_jobs);
  EXPECT_EQ(without.edge_witness_solves, 0);
  EXPECT_GT(with.bound_sources.count("feasible point at the box edge"), 0u);
  CompareEndpoints(with, without, [&](const std::string& name, std::size_t k, const Endpoint& x, const Endpoint& y,
                                      bool lower) {
    // An endpoint at the box edge is the relaxation's bound too (the SDP reaches it up to its accuracy).
    const double edge = lower ? set.box()[k].first : set.box()[k].second;
    if (x.value == edge) EXPECT_NEAR(y.value, edge, 1e-4) << name << (lower ? " lower" : " upper");
  });
  // The reported feasible points certify in their orthants, and each interval's witnessed range lies inside it
  // and is the range over those points; without the stage there are none.
  ASSERT_FALSE(with.feasible_points.empty());
  EXPECT_TRUE(without.feasible_points.empty());
  for (const auto& p : with.feasible_points) EXPECT_GE(CertifiedMinSlack(set, p.orthant, p.point), 0.0);
  const auto& names = set.layout().names;
  for (const auto& iv : with.intervals) {
    ASSERT_TRUE(iv.witnessed_lower && iv.witnessed_upper) << iv.name;
    const std::size_t k = std::find(names.begin(), names.end(), iv.name) - names.begin();
    double lo = INFINITY, hi = -INFINITY;
    for (const auto& p : with.feasible_points) lo = std::min(lo, p.point[k]), hi = std::max(hi, p.point[k]);
    EXPECT_EQ(*iv.witnessed_lower, lo) << iv.name;
    EXPECT_EQ(*iv.witnessed_upper, hi) << iv.name;
    EXPECT_LE(iv.lower.value, lo) << iv.name;
    EXPECT_GE(iv.upper.value, hi) << iv.name;
    EXPECT_FALSE(without.intervals[&iv - with.intervals.data()].witnessed_lower) << iv.name;
  }
  const auto json = with.to_json();
  EXPECT_EQ(json.at("feasible_points").size(), with.feasible_points.size());
  EXPECT_EQ(json.at("intervals")[0].at("witnessed").at("lower").get<double>(), *with.intervals[0].witnessed_lower);
}

TEST(EdgeWitness, OptionsAreChecked) {
  EdgeWitnessOptions o;
  std::string error;
  EXPECT_TRUE(o.IsValid(&error));
  o.random_starts = -1;
  EXPECT_FALSE(o.IsValid(&error));
  EXPECT_NE(error.find("random_starts"), std::string::npos);
  o = {};
  o.edge_tolerance = 0.5;
  EXPECT_FALSE(o.IsValid(&error));
}

}  // namespace
}  // namespace hw::dss
