// One gross outlier in a recording must not move Brouri's estimates, and is flagged by sample (issue item 5).
#include <gtest/gtest.h>

#include <string>

#include "estimators/brouri/workflow.hpp"

namespace hw::brouri {
namespace {

struct StepRun {
  StepPlan plan;
  std::vector<double> y;
};

StepRun PaperSteps(std::uint64_t seed) {
  StepRun r;
  r.plan = WorkflowConfig::Paper().steps;
  r.y = Simulate(BacklashHwSystem::PaperExample(), r.plan.Input(), r.plan.sample_time, seed).y;
  return r;
}

NonlinearEstimate Estimate(const StepRun& r, Summary* s) { return EstimateFromSteps(r.plan, {}, {}, r.y, s); }

TEST(BrouriOutliers, OneSpikeInADescendingHoldLeavesSdUnchanged) {
  auto run = PaperSteps(4);
  Summary clean_summary, spiked_summary;
  const auto clean = Estimate(run, &clean_summary);
  ASSERT_TRUE(clean_summary.ok) << clean_summary.message;
  EXPECT_TRUE(clean.warnings.find("outlier") == std::string::npos) << clean.warnings;
  // A 1e6 in the averaging window of the last descending hold (on the descending border).
  const std::size_t H = run.plan.hold_samples, holds = run.plan.Levels().size();
  const std::size_t k = holds * H - run.plan.average_samples / 2;
  run.y[k] = 1e6;
  const auto spiked = Estimate(run, &spiked_summary);
  ASSERT_TRUE(spiked_summary.ok) << spiked_summary.message;
  EXPECT_NEAR(spiked.params.slope_down, clean.params.slope_down, 1e-3 * std::abs(clean.params.slope_down));
  EXPECT_NEAR(spiked.params.offset_down, clean.params.offset_down, 1e-3);
  EXPECT_NEAR(spiked.params.offset_up, clean.params.offset_up, 1e-3);
  EXPECT_NE(spiked.warnings.find(std::to_string(k + 1)), std::string::npos) << spiked.warnings;
  EXPECT_NE(spiked_summary.message.find("outlier"), std::string::npos) << spiked_summary.message;
  ASSERT_EQ(spiked.down.back().outliers.size(), 1u);
  EXPECT_EQ(spiked.down.back().outliers[0], k);
}

TEST(BrouriOutliers, SpikeEarlyInAPlateauHoldKeepsThePlateau) {
  auto run = PaperSteps(5);
  Summary s0, s1;
  const auto clean = Estimate(run, &s0);
  ASSERT_TRUE(s0.ok) << s0.message;
  // Second ascending hold (on the plateau), before its averaging window: it enters the whole-hold mean.
  run.y[2 * run.plan.hold_samples + 3] = -1e6;
  const auto spiked = Estimate(run, &s1);
  ASSERT_TRUE(s1.ok) << s1.message;
  EXPECT_EQ(spiked.j_a, clean.j_a);
  EXPECT_EQ(spiked.j_d, clean.j_d);
  EXPECT_NEAR(spiked.params.slope_down, clean.params.slope_down, 1e-3 * std::abs(clean.params.slope_down));
}

TEST(BrouriOutliers, PeriodicAverageLeavesOutTheSpike) {
  const auto sys = BacklashHwSystem::PaperExample();
  Summary s;
  const auto est = Estimate(PaperSteps(6), &s);
  ASSERT_TRUE(s.ok) << s.message;
  const auto plan = MakeSinePlan(est, {0.05}, 1.0, 128, 8, 80.0);
  const auto& e = plan.experiments[0];
  auto y = Simulate(sys, plan.Input(0), e.sample_time(), 9).y;
  Summary c, d;
  const auto clean = EstimateFromSine(plan, 0, {}, {}, y, &c);
  const std::size_t k = static_cast<std::size_t>(e.transient_periods + 3) * e.samples_per_period + 17;
  y[k] = 1e6;
  const auto spiked = EstimateFromSine(plan, 0, {}, {}, y, &d);
  EXPECT_NEAR(spiked.gain, clean.gain, 1e-3 * clean.gain);
  EXPECT_NEAR(spiked.phase, clean.phase, 1e-3);
  ASSERT_EQ(spiked.outliers.size(), 1u);
  EXPECT_EQ(spiked.outliers[0], k);
  EXPECT_NE(d.message.find("outlier"), std::string::npos) << d.message;
  EXPECT_TRUE(clean.outliers.empty());
}

TEST(BrouriOutliers, CleanNoisyRecordingsFlagNothing) {
  for (std::uint64_t seed = 1; seed <= 40; ++seed) {
    const auto run = PaperSteps(seed);
    const auto holds = AverageHolds(run.y, run.plan.Levels(), run.plan.hold_samples, run.plan.average_samples);
    for (std::size_t j = 0; j < holds.size(); ++j) EXPECT_TRUE(holds[j].outliers.empty()) << "seed " << seed << " hold " << j;
  }
  const auto sys = BacklashHwSystem::PaperExample();
  Summary s;
  const auto est = Estimate(PaperSteps(1), &s);
  ASSERT_TRUE(s.ok) << s.message;
  const auto plan = MakeSinePlan(est, {0.02, 0.1}, 1.0, 128, 10, 80.0);
  for (std::uint64_t seed = 1; seed <= 10; ++seed)
    for (std::size_t i = 0; i < plan.experiments.size(); ++i) {
      const auto y = Simulate(sys, plan.Input(i), plan.experiments[i].sample_time(), seed).y;
      Summary d;
      EXPECT_TRUE(EstimateFromSine(plan, i, {}, {}, y, &d).outliers.empty()) << "seed " << seed << " sine " << i;
    }
}

}  // namespace
}  // namespace hw::brouri
