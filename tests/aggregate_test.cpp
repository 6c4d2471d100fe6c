// Stage 6 of the bound engine (dss/aggregate.hpp) on hand-made job outcomes: endpoints are the extreme
// orthant bounds, never beyond the prior box (an assumption of every result, said once), and failed jobs
// fall back without dropping their orthant.
#include <gtest/gtest.h>

#include "core/cerone_example.hpp"
#include "dss/aggregate.hpp"

namespace hw::dss {
namespace {

JobOutcome Solved(double bound) {
  JobOutcome r;
  r.status = "solved";
  r.bound = r.float_bound = bound;
  r.tight = true;
  r.verification = "verified";
  r.origin = "final round";
  return r;
}

struct Fixture {
  HwOuterSet set;
  std::vector<Objective> objectives{{4, -1}, {4, +1}};  // min and max of a1
  std::vector<OrthantWork> orthants;
  PassOutcomes outcomes;
  Fixture() : set(MakeSet()) {
    for (int l : {3, 7}) {
      OrthantWork w;
      w.index = l;
      w.box = set.box();
      orthants.push_back(w);
    }
  }
  static HwOuterSet MakeSet() {
    const auto ex = SimulateCeroneExample(1, 30, 31.0);
    HwData data{ex.u, ex.y, std::vector<double>(ex.y.size(), ex.noise_bound), "seeded"};
    return HwOuterSet(CeroneExampleStructure(), data, 1, std::vector<std::pair<double, double>>(8, {-2.0, 3.0}));
  }
  AggregateResult Run() const {
    return AggregateIntervals(AggregateOptions{true, 1, 1}, set, objectives, {4}, outcomes, outcomes, orthants);
  }
};

TEST(Aggregate, EndpointsBeyondThePriorBoxAreClippedAndSaidOnce) {
  Fixture f;
  // Rounding lets a relaxation's bound of the box edge fall just outside it (-2.000008 for the edge -2).
  f.outcomes[{3, 0}] = Solved(-2.000008);
  f.outcomes[{7, 0}] = Solved(-1.5);
  f.outcomes[{3, 1}] = Solved(2.5);
  f.outcomes[{7, 1}] = Solved(3.0000004);
  const AggregateResult r = f.Run();
  ASSERT_EQ(r.intervals.size(), 1u);
  EXPECT_EQ(r.intervals[0].lower.value, -2.0);
  EXPECT_EQ(r.intervals[0].upper.value, 3.0);
  EXPECT_EQ(r.intervals[0].lower.orthant, 3);
  EXPECT_EQ(r.intervals[0].upper.orthant, 7);
  EXPECT_TRUE(r.clipped_to_box);
}

TEST(Aggregate, InsideTheBoxNothingIsClippedAndTheExtremeOrthantWins) {
  Fixture f;
  f.outcomes[{3, 0}] = Solved(0.2);
  f.outcomes[{7, 0}] = Solved(0.1);
  f.outcomes[{3, 1}] = Solved(1.7);
  f.outcomes[{7, 1}] = Solved(1.9);
  const AggregateResult r = f.Run();
  EXPECT_EQ(r.intervals[0].lower.value, 0.1);
  EXPECT_EQ(r.intervals[0].upper.value, 1.9);
  EXPECT_FALSE(r.clipped_to_box);
  EXPECT_EQ(r.intervals[0].lower.status, "guaranteed");
}

TEST(Aggregate, AFailedJobFallsBackToTheBoxEdgeAndKeepsItsOrthant) {
  Fixture f;
  f.outcomes[{3, 0}] = Solved(0.2);
  JobOutcome failed;
  failed.status = "failed";
  failed.message = "solver trouble";
  f.outcomes[{7, 0}] = failed;
  f.outcomes[{3, 1}] = Solved(1.7);
  f.outcomes[{7, 1}] = Solved(1.9);
  const AggregateResult r = f.Run();
  EXPECT_EQ(r.intervals[0].lower.value, -2.0);  // orthant 7's box edge: valid, conservative
  EXPECT_EQ(r.intervals[0].lower.status, "conservative");
  EXPECT_EQ(r.sources.at("box edge"), 1);
}

// An order-delta job that stopped short can end looser than the cheap order's bound of the same orthant; both
// bound it, so the tighter one is the orthant's value (never looser than the cheap order: Property 3).
TEST(Aggregate, ACheapBoundTighterThanAShortOrderDeltaBoundIsUsed) {
  Fixture f;
  PassOutcomes cheap;
  cheap[{3, 0}] = Solved(0.30);
  cheap[{7, 0}] = Solved(0.50);
  cheap[{3, 1}] = Solved(1.90);
  cheap[{7, 1}] = Solved(1.70);
  PassOutcomes full;
  full[{3, 0}] = Solved(0.25);  // stopped short: looser than its cheap bound 0.30
  full[{3, 0}].tight = false;
  full[{3, 0}].unfinished = true;
  full[{7, 0}] = Solved(0.55);
  full[{3, 1}] = Solved(1.85);
  full[{7, 1}] = Solved(1.75);  // looser than 1.70 as well, but not the extreme orthant
  const AggregateResult r =
      AggregateIntervals(AggregateOptions{true, 3, 2}, f.set, f.objectives, {4}, cheap, full, f.orthants);
  EXPECT_EQ(r.intervals[0].lower.value, 0.30);
  EXPECT_EQ(r.intervals[0].lower.orthant, 3);
  EXPECT_EQ(r.intervals[0].lower.status, "guaranteed");
  EXPECT_FALSE(r.intervals[0].lower.tight);
  EXPECT_EQ(r.intervals[0].upper.value, 1.85);
  EXPECT_EQ(r.sources.at("cheap order (tighter than an order-delta job that stopped short)"), 2);
}

}  // namespace
}  // namespace hw::dss
