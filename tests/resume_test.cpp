// A run resumed from its run directory says so with how much of the earlier run is done, reads every finished
// job back, gives the same intervals, and its progress counts only the work still to run.
#include <filesystem>
#include <map>
#include <regex>

#include <gtest/gtest.h>

#include "core/cerone_example.hpp"
#include "dss/set_membership.hpp"

namespace hw::dss {
namespace {

namespace fs = std::filesystem;

struct Recorded {
  std::vector<std::string> messages;
  std::map<std::string, BoundsProgress> last;  // last event of each phase
};

// A small bounds run (one parameter, order 1) with a run directory of its own.
class Resume : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("hw_resume_test_" + std::string(
                                            ::testing::UnitTest::GetInstance()->current_test_info()->name()));
    fs::remove_all(dir_);
    options_.order = 1;
    options_.threads = 1;
    options_.parameters = {"a1"};
    options_.run_dir = dir_.string();
  }
  void TearDown() override { fs::remove_all(dir_); }

  BoundsSummary Run(Recorded* rec) {
    return ComputeBounds(options_, set_, [rec](const BoundsProgress& p) {
      if (p.total < 0) rec->messages.push_back(p.phase);
      else rec->last[p.phase] = p;
    });
  }

  // The finished job files in the run directory (one problem hash below it).
  std::vector<fs::path> JobFiles() const {
    std::vector<fs::path> files;
    for (const auto& e : fs::recursive_directory_iterator(dir_))
      if (e.path().parent_path().filename() == "jobs" && e.path().extension() == ".json") files.push_back(e.path());
    return files;
  }

  const CeroneExample ex_ = SimulateCeroneExample(4, 40, 31.0);
  const HwOuterSet set_{CeroneExampleStructure(),
                        HwData{ex_.u, ex_.y, std::vector<double>(ex_.y.size(), ex_.noise_bound), "seeded"}, 1,
                        std::vector<std::pair<double, double>>(8, {-10.0, 10.0})};
  fs::path dir_;
  BoundsOptions options_;
};

// "resuming: K of M jobs planned so far ..." -> (K, M); (-1, -1) when the line has no such counts.
std::pair<int, int> ResumeCounts(const std::string& line) {
  std::smatch m;
  if (!std::regex_search(line, m, std::regex("^resuming: (\\d+) of (\\d+) jobs planned so far are finished")))
    return {-1, -1};
  return {std::stoi(m[1]), std::stoi(m[2])};
}

TEST_F(Resume, RerunReadsEveryJobBackAndCountsOnlyWhatIsLeft) {
  Recorded first, second;
  const BoundsSummary a = Run(&first);
  const int jobs = static_cast<int>(JobFiles().size());
  const BoundsSummary b = Run(&second);
  EXPECT_TRUE(first.messages.empty()) << "a fresh run directory resumes nothing";
  EXPECT_EQ(a.jobs_from_cache, 0);
  EXPECT_GT(b.jobs_from_cache, 0);
  EXPECT_EQ(b.sdp_jobs, 0) << "every relaxation job is read back";
  ASSERT_FALSE(second.messages.empty());
  EXPECT_EQ(ResumeCounts(second.messages.front()), std::make_pair(jobs, jobs)) << second.messages.front();
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
}

// An interrupted run leaves some planned jobs unfinished: the resume line counts them against the earlier plan,
// not against what happens to be on disk.
TEST_F(Resume, ResumeLineCountsFinishedJobsAgainstTheEarlierPlan) {
  Recorded first, second;
  const BoundsSummary a = Run(&first);
  std::vector<fs::path> files = JobFiles();
  const int planned = static_cast<int>(files.size());
  ASSERT_GT(planned, 3);
  for (int k = 0; k < 3; ++k) fs::remove(files[k]);  // as if the earlier run had stopped before these finished
  const BoundsSummary b = Run(&second);
  ASSERT_FALSE(second.messages.empty());
  EXPECT_EQ(ResumeCounts(second.messages.front()), std::make_pair(planned - 3, planned)) << second.messages.front();
  EXPECT_EQ(static_cast<int>(JobFiles().size()), planned) << "the missing jobs are run again";
  ASSERT_EQ(a.intervals.size(), b.intervals.size());
  for (std::size_t k = 0; k < a.intervals.size(); ++k) {
    EXPECT_EQ(a.intervals[k].lower.value, b.intervals[k].lower.value);
    EXPECT_EQ(a.intervals[k].upper.value, b.intervals[k].upper.value);
  }
}

// Runs of different orders share the run directory: an order-1 run reads back the LP screen of an order-2
// run (the order is in each relaxation job's name, not in the problem's key) and gives the intervals of an
// order-1 run in a fresh directory.
TEST_F(Resume, RunsOfAnotherOrderReadBackTheJobsTheyShare) {
  Recorded first, second, fresh;
  options_.order = 2;
  options_.threads = 2;
  Run(&first);
  options_.order = 1;
  const BoundsSummary shared = Run(&second);
  EXPECT_GT(shared.jobs_from_cache, 0);
  ASSERT_TRUE(second.last.count("LP screen of orthants"));
  EXPECT_EQ(second.last["LP screen of orthants"].total, 0) << "the screen is the order-2 run's";
  EXPECT_GT(shared.sdp_jobs, 0) << "the order-1 relaxations are new";
  options_.run_dir = (dir_ / "fresh").string();
  const BoundsSummary alone = Run(&fresh);
  EXPECT_EQ(alone.jobs_from_cache, 0);
  ASSERT_EQ(shared.intervals.size(), alone.intervals.size());
  for (std::size_t k = 0; k < shared.intervals.size(); ++k) {
    EXPECT_EQ(shared.intervals[k].lower.value, alone.intervals[k].lower.value);
    EXPECT_EQ(shared.intervals[k].upper.value, alone.intervals[k].upper.value);
  }
}

}  // namespace
}  // namespace hw::dss
