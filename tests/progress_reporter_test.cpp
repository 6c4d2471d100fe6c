// The progress of a bounds run (dss/progress_reporter.hpp): jobs done / total per phase, and the best bound so far,
// the interval of the parameter bounded last over the phase's finished jobs.
#include <vector>

#include <gtest/gtest.h>

#include "dss/progress_reporter.hpp"

namespace hw::dss {
namespace {

TEST(ProgressReporter, EachEventCarriesTheIntervalSoFarOfTheParameterBoundedLast) {
  std::vector<BoundsProgress> events;
  ProgressReporter progress([&](const BoundsProgress& p) { events.push_back(p); });
  progress.Phase("order 2 relaxations", 4);
  ASSERT_EQ(events.size(), 1u);
  EXPECT_TRUE(events.back().so_far_parameter.empty()) << "no job has bounded anything yet";
  progress.Bound("a1", -1, 0.9);
  progress.Done();
  EXPECT_EQ(events.back().so_far_parameter, "a1");
  EXPECT_EQ(events.back().so_far_lower, 0.9);
  EXPECT_FALSE(events.back().so_far_upper.has_value()) << "no upper bound of a1 yet";
  progress.Bound("a1", +1, 2.5);
  progress.Done();
  progress.Bound("a1", -1, 1.2);  // another orthant's lower bound, inside: the interval so far keeps 0.9
  progress.Done();
  EXPECT_EQ(events.back().done, 3);
  EXPECT_EQ(events.back().so_far_lower, 0.9);
  EXPECT_EQ(events.back().so_far_upper, 2.5);
  progress.Bound("a2", +1, 1.5);
  progress.Done();
  EXPECT_EQ(events.back().so_far_parameter, "a2");
  EXPECT_FALSE(events.back().so_far_lower.has_value());
  EXPECT_EQ(events.back().so_far_upper, 1.5);
  progress.Phase("order 3 relaxations", 2);  // a new phase starts from nothing
  EXPECT_TRUE(events.back().so_far_parameter.empty());
  EXPECT_EQ(events.back().done, 0);
  EXPECT_EQ(events.back().elapsed_seconds, 0.0);
}

TEST(ProgressReporter, JobsReadFromTheCacheLeaveTheTotalButTheirBoundsCount) {
  std::vector<BoundsProgress> events;
  ProgressReporter progress([&](const BoundsProgress& p) { events.push_back(p); });
  progress.Phase("order 2 relaxations", 3);
  progress.FromCache(2);
  EXPECT_EQ(events.back().total, 1);
  EXPECT_EQ(events.back().from_cache, 2);
  for (double bound : {0.5, 0.7}) {  // the cached jobs' answers: not counted as done
    progress.Bound("b1", -1, bound);
    progress.Done();
  }
  EXPECT_EQ(events.back().done, 0);
  progress.Bound("b1", -1, 0.6);
  progress.Done();
  EXPECT_EQ(events.back().done, 1);
  EXPECT_EQ(events.back().so_far_lower, 0.5);
}

}  // namespace
}  // namespace hw::dss
