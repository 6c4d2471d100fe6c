// Inner witnesses (feasible points of D^ss(n) found by local optimisation) against the relaxation's outer
// intervals: every witness must lie inside every guaranteed interval. This checks the guarantee from the
// other side than coverage of the truth: a relaxation that cut off part of D^ss(n) fails here.
#include <gtest/gtest.h>

#include "core/cerone_example.hpp"
#include "dss/inner_points.hpp"
#include "dss/set_membership.hpp"

extern "C" int openblas_get_num_threads();

namespace hw::dss {
namespace {

TEST(InnerPoints, WitnessesAreFeasibleAndInsideTheGuaranteedIntervals) {
  for (uint64_t seed : {11u, 12u}) {
    const auto ex = SimulateCeroneExample(seed, 60, 31.0);
    HwData data{ex.u, ex.y, std::vector<double>(ex.y.size(), ex.noise_bound), "seeded"};
    HwOuterSet set(CeroneExampleStructure(), data, 1, std::vector<std::pair<double, double>>(8, {-10.0, 10.0}));
    const auto truth = CeroneExample::TrueParameters();
    ASSERT_GE(set.min_slack(truth), 0.0);
    BoundsOptions options;
    options.order = 1;
    options.solver = "csdp";
    options.threads = 2;
    const auto outer = ComputeBounds(options, set);
    const int l = set.orthant_of(truth);
    int found = 0;
    for (int k = 0; k < set.num_vars(); ++k) {
      const auto& iv = outer.intervals[k];
      for (int dir : {-1, +1}) {
        const auto w = LocalExtreme(set, l, k, dir, truth);
        if (!w.found) continue;
        ++found;
        EXPECT_GE(w.min_slack, 0.0);
        EXPECT_EQ(set.orthant_of(w.point), l);
        EXPECT_GE(set.min_slack(w.point), 0.0);
        // The witness moved the right way from the truth (a local extreme, not just any point) ...
        EXPECT_GE(dir * (w.value - truth[k]), -1e-9) << iv.name;
        // ... and no valid outer interval may exclude it.
        EXPECT_LE(iv.lower.value, w.value + 1e-6) << "seed " << seed << " " << iv.name;
        EXPECT_GE(iv.upper.value, w.value - 1e-6) << "seed " << seed << " " << iv.name;
      }
    }
    EXPECT_GE(found, 12) << "local optimisation from a strictly feasible truth should succeed for most objectives";
  }
}

// Inner hulls run local solves one after another beside parallel SDP workers: MUMPS under Ipopt must not
// start one OpenBLAS thread per core (they spin in sched_yield and take the workers' cores). ctest runs each
// test in its own process, so no SDP solve has set the thread count before this one.
TEST(InnerPoints, LocalSolvesUseOneBlasThread) {
  if (openblas_get_num_threads() == 1)
    GTEST_SKIP() << "OpenBLAS already starts with one thread here (one core, or OPENBLAS_NUM_THREADS=1)";
  const auto ex = SimulateCeroneExample(11, 60, 31.0);
  HwData data{ex.u, ex.y, std::vector<double>(ex.y.size(), ex.noise_bound), "seeded"};
  HwOuterSet set(CeroneExampleStructure(), data, 1, std::vector<std::pair<double, double>>(8, {-10.0, 10.0}));
  const auto truth = CeroneExample::TrueParameters();
  const auto w = LocalExtreme(set, set.orthant_of(truth), 0, +1, truth);
  EXPECT_TRUE(w.found) << w.message;
  EXPECT_EQ(openblas_get_num_threads(), 1);
}

TEST(InnerPoints, AnInfeasibleRegionGivesNoWitness) {
  const auto ex = SimulateCeroneExample(13, 60, 31.0);
  HwData data{ex.u, ex.y, std::vector<double>(ex.y.size(), ex.noise_bound), "seeded"};
  HwOuterSet set(CeroneExampleStructure(), data, 1, std::vector<std::pair<double, double>>(8, {-10.0, 10.0}));
  // An orthant proven empty has no feasible point: whatever Ipopt returns must fail the evaluation check.
  const auto truth = CeroneExample::TrueParameters();
  const int l_true = set.orthant_of(truth);
  int rejected = 0;
  for (int l = 0; l < set.num_orthants(); ++l) {
    if (l == l_true) continue;
    const auto w = LocalExtreme(set, l, 4, +1, truth);
    if (w.found) {
      EXPECT_GE(set.min_slack(w.point), 0.0);
      EXPECT_EQ(set.orthant_of(w.point), l);
    } else {
      ++rejected;
    }
  }
  EXPECT_GT(rejected, 0);
}

}  // namespace
}  // namespace hw::dss
