// Feasible points from the relaxations' first moments (dss/moment_witness.hpp): the stage leaves every bound as
// it is, its points certify in their orthants and lie inside the intervals, and they reach further towards the
// endpoints than the points the other stages find.
#include <cmath>

#include <gtest/gtest.h>

#include "core/cerone_example.hpp"
#include "dss/relax_job.hpp"
#include "dss/edge_witness.hpp"
#include "dss/set_membership.hpp"
#include "seeded_example.hpp"

namespace hw::dss {
namespace {

TEST(MomentWitness, FirstMomentsSurviveTheRunCache) {
  JobOutcome o;
  o.status = JobStatus::kSolved;
  o.first_moments = {0.25, -1.5, 3.0};
  EXPECT_EQ(JobOutcome::from_json(o.to_json()).first_moments, o.first_moments);
  auto older = o.to_json();  // a job cached before the field existed
  older.erase("first_moments");
  EXPECT_TRUE(JobOutcome::from_json(older).first_moments.empty());
}

TEST(MomentWitness, PointsCertifyAndNarrowTheUnwitnessedPartWithoutMovingABound) {
  // n = 2, 45 dB: the set is a small region around the truth, where searches from the relaxations' moments
  // reach the a1 and a2 extremes; the edge-witness stage finds no point at the prior box edge.
  const HwOuterSet set = SeededSet(3, 60, 2, 45.0, 10.0);
  BoundsOptions options;
  options.order = 2;
  options.threads = 2;
  options.parameters = {"a1", "a2"};
  const BoundsSummary with = ComputeBounds(options, set);
  options.moment_witnesses = false;
  const BoundsSummary without = ComputeBounds(options, set);
  ASSERT_GT(with.moment_witness_jobs, 0) << "no solved job with moments: the instance no longer exercises the stage";
  EXPECT_GT(with.moment_witness_found, 0);
  EXPECT_EQ(without.moment_witness_jobs, 0);
  CompareEndpoints(with, without, [](const std::string& name, std::size_t, const Endpoint& x, const Endpoint& y,
                                     bool lower) {
    EXPECT_EQ(x.value, y.value) << name << (lower ? " lower" : " upper") << ": the stage must not move a bound";
  });
  for (const auto& p : with.feasible_points) EXPECT_GE(CertifiedMinSlack(set, p.orthant, p.point), 0.0);
  const auto truth = CeroneExample::TrueParameters();
  for (std::size_t i = 0; i < with.intervals.size(); ++i) {
    const auto& iv = with.intervals[i];
    const std::size_t k = ParameterIndex(with, iv.name);
    ASSERT_TRUE(iv.witnessed_lower && iv.witnessed_upper) << iv.name;
    EXPECT_LE(iv.lower.value, *iv.witnessed_lower) << iv.name;
    EXPECT_GE(iv.upper.value, *iv.witnessed_upper) << iv.name;
    // The searches from the moments end beyond the truth on both sides (a search around the truth alone need not).
    EXPECT_LT(*iv.witnessed_lower, truth[k]) << iv.name;
    EXPECT_GT(*iv.witnessed_upper, truth[k]) << iv.name;
    // What the relaxation may still overestimate shrinks (or stays) with the stage.
    const auto& other = without.intervals[i];
    if (other.witnessed_lower) {
      EXPECT_LE(*iv.witnessed_lower, *other.witnessed_lower) << iv.name;
      EXPECT_GE(*iv.witnessed_upper, *other.witnessed_upper) << iv.name;
    }
  }
  EXPECT_EQ(with.to_json().at("counts").at("moment_witness_found").get<int>(), with.moment_witness_found);
}

}  // namespace
}  // namespace hw::dss
