// A run resumed from its run directory says so, reads every finished job back, gives the same intervals, and
// its progress counts only the work still to run.
#include <filesystem>
#include <map>

#include <gtest/gtest.h>

#include "core/cerone_example.hpp"
#include "relax/set_membership.hpp"

namespace hw::relax {
namespace {

struct Recorded {
  std::vector<std::string> messages;
  std::map<std::string, BoundsProgress> last;  // last event of each phase
};

TEST(Resume, RerunReadsEveryJobBackAndCountsOnlyWhatIsLeft) {
  const auto ex = SimulateCeroneExample(4, 40, 31.0);
  HwData data{ex.u, ex.y, std::vector<double>(ex.y.size(), ex.noise_bound), "seeded"};
  HwOuterSet set(CeroneExampleStructure(), data, 1, std::vector<std::pair<double, double>>(8, {-10.0, 10.0}));
  const auto dir = std::filesystem::temp_directory_path() / "hw_resume_test";
  std::filesystem::remove_all(dir);
  BoundsOptions options;
  options.order = 1;
  options.threads = 1;
  options.parameters = {"a1"};
  options.run_dir = dir.string();
  auto run = [&](Recorded* rec) {
    return ComputeBounds(options, set, [rec](const BoundsProgress& p) {
      if (p.total < 0) rec->messages.push_back(p.phase);
      else rec->last[p.phase] = p;
    });
  };
  Recorded first, second;
  const BoundsSummary a = run(&first);
  const BoundsSummary b = run(&second);
  EXPECT_EQ(a.jobs_from_cache, 0);
  EXPECT_GT(b.jobs_from_cache, 0);
  EXPECT_EQ(b.sdp_jobs, 0) << "every relaxation job is read back";
  ASSERT_FALSE(second.messages.empty());
  EXPECT_EQ(second.messages.front().rfind("resuming: ", 0), 0u) << second.messages.front();
  for (const char* phase : {"LP screen of orthants", "order 1 relaxations"}) {
    ASSERT_TRUE(first.last.count(phase)) << phase;
    ASSERT_TRUE(second.last.count(phase)) << phase;
    EXPECT_EQ(second.last[phase].total, 0) << phase << ": nothing is left to run";
    EXPECT_EQ(second.last[phase].from_cache, first.last[phase].total) << phase;
  }
  ASSERT_EQ(a.intervals.size(), b.intervals.size());
  for (std::size_t k = 0; k < a.intervals.size(); ++k) {
    EXPECT_EQ(a.intervals[k].lower.value, b.intervals[k].lower.value);
    EXPECT_EQ(a.intervals[k].upper.value, b.intervals[k].upper.value);
  }
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace hw::relax
