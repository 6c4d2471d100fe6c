// A signal that ends the parent ends its forked workers (issue item 6): no worker is left running with
// PPID 1. The test process makes itself a child subreaper, so that workers orphaned by their parent's death
// become its children and can be watched (and, on failure, killed) here.
#include <gtest/gtest.h>

#include <fcntl.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <set>
#include <string>
#include <thread>

#include "core/cerone_example.hpp"
#include "core/csv_table.hpp"
#include "sdp/job_executor.hpp"

namespace hw {
namespace {

using Clock = std::chrono::steady_clock;

// Pids of the live (not zombie) processes whose parent is `parent`.
std::set<pid_t> ChildrenOf(pid_t parent) {
  std::set<pid_t> out;
  for (const auto& e : std::filesystem::directory_iterator("/proc")) {
    const std::string name = e.path().filename().string();
    if (name.find_first_not_of("0123456789") != std::string::npos) continue;
    std::ifstream in(e.path() / "stat");
    std::string stat;
    std::getline(in, stat);
    const auto close = stat.rfind(')');  // the command name may hold spaces and parentheses
    if (close == std::string::npos) continue;
    char state = 0;
    long ppid = 0;
    if (std::sscanf(stat.c_str() + close + 1, " %c %ld", &state, &ppid) == 2 && ppid == parent && state != 'Z')
      out.insert(static_cast<pid_t>(std::stol(name)));
  }
  return out;
}

// Waits until every pid in `workers` has ended (reaped by us as subreaper, or gone); kills the survivors.
// Returns how many were still running after `patience`.
int SurvivorsAfter(const std::set<pid_t>& workers, std::chrono::milliseconds patience) {
  std::set<pid_t> alive = workers;
  const auto end = Clock::now() + patience;
  while (!alive.empty() && Clock::now() < end) {
    for (auto it = alive.begin(); it != alive.end();) {
      const bool gone = ::waitpid(*it, nullptr, WNOHANG) == *it || ::kill(*it, 0) != 0;
      it = gone ? alive.erase(it) : std::next(it);
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  for (pid_t p : alive) {
    ::kill(p, SIGKILL);
    ::waitpid(p, nullptr, 0);
  }
  return static_cast<int>(alive.size());
}

class WorkerSignals : public ::testing::Test {
 protected:
  void SetUp() override { ASSERT_EQ(::prctl(PR_SET_CHILD_SUBREAPER, 1), 0); }
};

// A parent process running ForkExecutor::Map over jobs that would take a minute; `signal` ends the parent.
void ExpectWorkersEndWithTheParent(int signal) {
  const pid_t parent = ::fork();
  ASSERT_GE(parent, 0);
  if (parent == 0) {
    sdp::ForkExecutor executor(2);
    executor.Map({"a", "b", "c"}, [](const std::string& s) {
      std::this_thread::sleep_for(std::chrono::seconds(60));
      return s;
    });
    ::_exit(0);
  }
  std::set<pid_t> workers;
  for (const auto end = Clock::now() + std::chrono::seconds(10); workers.size() < 2 && Clock::now() < end;) {
    workers = ChildrenOf(parent);
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  ASSERT_EQ(workers.size(), 2u) << "the parent did not start its two workers";
  ::kill(parent, signal);
  int status = 0;
  ASSERT_EQ(::waitpid(parent, &status, 0), parent);
  EXPECT_TRUE(WIFSIGNALED(status));
  EXPECT_EQ(SurvivorsAfter(workers, std::chrono::seconds(3)), 0) << "workers outlived their parent (signal " << signal << ")";
}

TEST_F(WorkerSignals, ForkExecutorWorkersEndWhenTheParentIsKilled) {
  ExpectWorkersEndWithTheParent(SIGKILL);
  ExpectWorkersEndWithTheParent(SIGTERM);
}

#ifdef HW_CLI_PATH
// SIGINT to a running `hwbounds bounds` (not to its process group, as a terminal's Ctrl-C would) leaves
// no worker behind. Order 2 at horizon 1 makes each relaxation job last long enough to be caught running.
TEST_F(WorkerSignals, InterruptedBoundsRunLeavesNoWorker) {
  const std::string dir = ::testing::TempDir();
  const auto ex = SimulateCeroneExample(7, 50);
  CsvTable t;
  t.names = {"u", "y"};
  t.columns = {ex.u, ex.y};
  write_csv(dir + "/signal_case.csv", t);
  const std::string data = dir + "/signal_case.csv", noise = std::to_string(ex.noise_bound);
  const pid_t cli = ::fork();
  ASSERT_GE(cli, 0);
  if (cli == 0) {
    const int null = ::open("/dev/null", O_WRONLY);
    ::dup2(null, 1);
    ::dup2(null, 2);
    ::execl(HW_CLI_PATH, HW_CLI_PATH, "bounds", "--data", data.c_str(), "--noise-bound", noise.c_str(), "--horizon",
            "1", "--order", "2", "--no-cheap-pass", "--threads", "2", "--solver", "csdp", "--quiet", nullptr);
    ::_exit(127);
  }
  // Wait for a worker that has been running for a while (a relaxation job, not a quick LP screen).
  std::set<pid_t> seen_at_start, caught;
  auto first_seen = Clock::now();
  for (const auto end = Clock::now() + std::chrono::seconds(60); caught.empty() && Clock::now() < end;) {
    const auto now = ChildrenOf(cli);
    std::set<pid_t> both;
    for (pid_t p : now)
      if (seen_at_start.count(p)) both.insert(p);
    if (!both.empty() && Clock::now() - first_seen > std::chrono::milliseconds(200)) caught = now;
    if (both.empty()) seen_at_start = now, first_seen = Clock::now();
    if (::waitpid(cli, nullptr, WNOHANG) == cli) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  ASSERT_FALSE(caught.empty()) << "no relaxation worker was seen running";
  ::kill(cli, SIGINT);
  int status = 0;
  ASSERT_EQ(::waitpid(cli, &status, 0), cli);
  EXPECT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGINT);
  EXPECT_EQ(SurvivorsAfter(caught, std::chrono::seconds(3)), 0) << "bounds workers outlived the interrupted run";
}
#endif

}  // namespace
}  // namespace hw
