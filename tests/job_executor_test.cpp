// Executors for independent SDP jobs: forked workers return every answer in order, a job that crashes its
// process comes back as a failure with the reason (never lost, never fatal to the run), and an MPI run of the
// set-membership engine gives the same intervals as the local run.
#include <sys/wait.h>

#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdlib>
#include <fstream>
#include <set>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "core/cerone_example.hpp"
#include "core/csv_table.hpp"
#include "sdp/job_executor.hpp"

namespace hw::sdp {
namespace {

TEST(ForkExecutor, AnswersEveryJobInOrderFromOtherProcesses) {
  ForkExecutor exec(2);
  std::vector<std::string> specs;
  for (int i = 0; i < 9; ++i) specs.push_back(std::to_string(i));
  std::set<std::size_t> seen;
  const auto out = exec.Map(
      specs, [](const std::string& s) { return std::to_string(std::stoi(s) * std::stoi(s)) + ":" + std::to_string(getpid()); },
      [&](std::size_t i, const JobResult& r) {
        EXPECT_TRUE(r.ok);
        EXPECT_TRUE(seen.insert(i).second) << "job reported twice";
      });
  ASSERT_EQ(out.size(), specs.size());
  EXPECT_EQ(seen.size(), specs.size());
  for (int i = 0; i < 9; ++i) {
    ASSERT_TRUE(out[i].ok) << out[i].error;
    const auto colon = out[i].text.find(':');
    EXPECT_EQ(out[i].text.substr(0, colon), std::to_string(i * i));
    EXPECT_NE(std::stoi(out[i].text.substr(colon + 1)), getpid()) << "job ran in the coordinator";
  }
}

TEST(ForkExecutor, CrashesAndExceptionsBecomeFailedResults) {
  ForkExecutor exec(2);
  const auto out = exec.Map({"ok", "exit", "abort", "throw", "big"}, [](const std::string& s) -> std::string {
    if (s == "exit") std::exit(7);  // what CSDP does on some errors
    if (s == "abort") std::abort();
    if (s == "throw") throw std::runtime_error("bad spec");
    if (s == "big") return std::string(1 << 20, 'x');  // larger than a pipe buffer
    return "fine";
  });
  ASSERT_EQ(out.size(), 5u);
  EXPECT_TRUE(out[0].ok);
  EXPECT_EQ(out[0].text, "fine");
  EXPECT_FALSE(out[1].ok);
  EXPECT_NE(out[1].error.find("status 7"), std::string::npos) << out[1].error;
  EXPECT_FALSE(out[2].ok);
  EXPECT_NE(out[2].error.find("signal"), std::string::npos) << out[2].error;
  EXPECT_FALSE(out[3].ok);
  EXPECT_EQ(out[3].error, "bad spec");
  EXPECT_TRUE(out[4].ok);
  EXPECT_EQ(out[4].text.size(), std::size_t{1} << 20);
}

// True when this process has no child process left (every worker was reaped).
bool NoChildrenLeft() { return ::waitpid(-1, nullptr, WNOHANG) < 0 && errno == ECHILD; }

double SecondsSince(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// A host's interrupt (Python's Ctrl-C) ends Map promptly even while every worker is busy, and leaves no
// worker process behind.
TEST(ForkExecutor, InterruptCheckStopsTheRunAndKillsItsWorkers) {
  ForkExecutor exec(2);
  int checks = 0;
  exec.set_interrupt_check([&] {
    if (++checks == 3) throw std::runtime_error("interrupted");
  });
  const auto t0 = std::chrono::steady_clock::now();
  EXPECT_THROW(exec.Map({"a", "b", "c"}, [](const std::string&) -> std::string {
    ::sleep(60);
    return "late";
  }), std::runtime_error);
  EXPECT_LT(SecondsSince(t0), 10.0);
  EXPECT_TRUE(NoChildrenLeft());
}

TEST(ForkExecutor, ExceptionFromOnDoneLeavesNoWorkerBehind) {
  ForkExecutor exec(3);
  const auto t0 = std::chrono::steady_clock::now();
  EXPECT_THROW(exec.Map({"fast", "slow", "slow"},
                        [](const std::string& s) -> std::string {
                          if (s == "slow") ::sleep(60);
                          return s;
                        },
                        [](std::size_t, const JobResult&) { throw std::runtime_error("stop"); }),
               std::runtime_error);
  EXPECT_LT(SecondsSince(t0), 10.0);
  EXPECT_TRUE(NoChildrenLeft());
}

TEST(InProcessExecutor, InterruptCheckRunsBeforeEachJob) {
  InProcessExecutor exec;
  int ran = 0;
  exec.set_interrupt_check([&] {
    if (ran == 2) throw std::runtime_error("interrupted");
  });
  EXPECT_THROW(exec.Map({"a", "b", "c"}, [&](const std::string& s) { ++ran; return s; }), std::runtime_error);
  EXPECT_EQ(ran, 2);
}

TEST(InProcessExecutor, SameAnswersAsFork) {
  InProcessExecutor a;
  ForkExecutor b(3);
  const std::vector<std::string> specs{"a", "bb", "ccc"};
  auto fn = [](const std::string& s) { return std::to_string(s.size()); };
  const auto ra = a.Map(specs, fn), rb = b.Map(specs, fn);
  for (std::size_t i = 0; i < specs.size(); ++i) EXPECT_EQ(ra[i].text, rb[i].text);
  EXPECT_THROW(MakeExecutor("cluster", 1), std::invalid_argument);
}

#if defined(HW_HAVE_MPI) && defined(HW_CLI_PATH)
// The whole engine under mpirun (3 ranks: coordinator + 2 workers) against the local fork run, with `extra`
// bounds options; `name` keeps the two cases' files apart.
void ExpectMpiIntervalsEqualTheLocalRun(const std::string& name, const std::string& extra) {
  const std::string dir = ::testing::TempDir();
  const auto ex = SimulateCeroneExample(5, 60);
  CsvTable t;
  t.names = {"u", "y"};
  t.columns = {ex.u, ex.y};
  write_csv(dir + "/mpi_case.csv", t);
  const std::string common = std::string(HW_CLI_PATH) + " bounds --data " + dir + "/mpi_case.csv --noise-bound " +
                             std::to_string(ex.noise_bound) + " --horizon 1 --order 1 --solver csdp --quiet" + extra;
  ASSERT_EQ(std::system((common + " --json " + dir + "/" + name + "_local.json > /dev/null").c_str()), 0);
  const std::string mpi = "mpirun --allow-run-as-root --oversubscribe -np 3 " + common + " --executor mpi --json " +
                          dir + "/" + name + "_mpi.json > " + dir + "/" + name + "_mpi.log 2>&1";
  const int rc = std::system(mpi.c_str());
  ASSERT_EQ(rc, 0) << "mpirun failed; see " << dir << "/" << name << "_mpi.log";
  nlohmann::json a, b;
  std::ifstream(dir + "/" + name + "_local.json") >> a;
  std::ifstream(dir + "/" + name + "_mpi.json") >> b;
  EXPECT_NE(b.at("executor").get<std::string>().find("mpi (2 workers)"), std::string::npos);
  ASSERT_EQ(a.at("intervals").size(), b.at("intervals").size());
  for (std::size_t i = 0; i < a.at("intervals").size(); ++i)
    for (const char* side : {"lower", "upper"}) {
      EXPECT_NEAR(a["intervals"][i][side]["value"].get<double>(), b["intervals"][i][side]["value"].get<double>(), 1e-9);
      EXPECT_EQ(a["intervals"][i][side]["status"], b["intervals"][i][side]["status"]);
    }
  EXPECT_EQ(a["counts"]["orthants_proven_empty"], b["counts"]["orthants_proven_empty"]);
  EXPECT_EQ(a.value("pieces", nlohmann::json::array()).size(), b.value("pieces", nlohmann::json::array()).size());
}

TEST(MpiExecutor, SameIntervalsAsTheLocalRun) {
  if (std::system("command -v mpirun > /dev/null 2>&1") != 0) GTEST_SKIP() << "mpirun not installed";
  ExpectMpiIntervalsEqualTheLocalRun("whole", "");
}

// A split box runs one MPI session per piece: the worker ranks serve them in turn.
TEST(MpiExecutor, SplitBoxSameIntervalsAsTheLocalRun) {
  if (std::system("command -v mpirun > /dev/null 2>&1") != 0) GTEST_SKIP() << "mpirun not installed";
  ExpectMpiIntervalsEqualTheLocalRun("split", " --split a1=-0.5,1.8");
}
#endif

}  // namespace
}  // namespace hw::sdp
