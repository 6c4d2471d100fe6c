// The command line checks what it is given before any work and reports honestly (issue items 4, 7, 8, 9, 12):
// conflicting or meaningless options are errors, output paths are checked first, nothing is written when a
// command fails, oversized relaxations are refused with their numbers, and --help shows the defaults.
#include <gtest/gtest.h>

#include <sys/wait.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include <nlohmann/json.hpp>

#include "core/cerone_example.hpp"
#include "core/csv_table.hpp"
#include "tests/test_support.hpp"

#ifdef HW_CLI_PATH
namespace hw {
namespace {

namespace fs = std::filesystem;

using testing_support::Has;
using Run = testing_support::CliRun;
Run Cli(const std::string& args) { return testing_support::RunCli(args); }

class CliIo : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::path(::testing::TempDir()) / ("cli_io_" + std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    const auto ex = SimulateCeroneExample(2, 40);
    CsvTable t;
    t.add_column("u", ex.u);
    t.add_column("y", ex.y);
    t.add_column("noise_bound", std::vector<double>(ex.y.size(), ex.noise_bound));
    write_csv(Path("rec.csv"), t);
  }
  std::string Path(const std::string& name) const { return (dir_ / name).string(); }
  std::string Bounds(const std::string& extra) const {
    return "bounds --data " + Path("rec.csv") + " --noise-col noise_bound --horizon 1 --quiet " + extra;
  }
  // Each (arguments, message) pair exits 2 naming `option` and the message, before any work.
  void ExpectRefusedBeforeAnyWork(const std::vector<std::pair<std::string, std::string>>& bad,
                                  const std::string& option) const {
    for (const auto& [args, message] : bad) {
      const auto r = Cli(Bounds(args));
      EXPECT_EQ(r.code, 2) << args << ": " << r.output;
      EXPECT_TRUE(Has(r.output, option)) << args << ": " << r.output;
      EXPECT_TRUE(Has(r.output, message)) << args << ": " << r.output;
      EXPECT_FALSE(Has(r.output, "orthants:")) << "it ran: " << r.output;
    }
  }
  fs::path dir_;
};

TEST_F(CliIo, ConflictingNoiseOptionsAreAnError) {
  const auto r = Cli(Bounds("--noise-bound 0.1"));
  EXPECT_NE(r.code, 0) << r.output;
  EXPECT_TRUE(Has(r.output, "--noise-bound") && Has(r.output, "--noise-col")) << r.output;
}

TEST_F(CliIo, OrderZeroOrNegativeIsAnError) {
  for (const char* order : {"0", "-3"}) {
    const auto r = Cli(Bounds(std::string("--order ") + order));
    EXPECT_NE(r.code, 0) << order << ": " << r.output;
    EXPECT_TRUE(Has(r.output, "--order")) << r.output;
    EXPECT_FALSE(Has(r.output, "orthants:")) << "it ran: " << r.output;
  }
  const auto pop = Cli(std::string("pop ") + HW_SOURCE_DIR + "/paper_examples/problems/gloptipoly_constrained.json --order 0");
  EXPECT_NE(pop.code, 0) << pop.output;
}

TEST_F(CliIo, BadSplitIsNamedBeforeAnyWork) {
  const std::vector<std::pair<std::string, std::string>> bad = {
      {"--split a1", "expected NAME=VALUE[,VALUE...]"},
      {"--split a1=x", "'x' is not a number"},
      {"--split a1=0.5x", "'0.5x' is not a number"},
      {"--split a7=0", "no parameter 'a7'"},
      {"--split a1=10", "not strictly inside its prior box side [-10, 10]"},
      {"--box a1=0,3 --split a1=-1", "not strictly inside its prior box side [0, 3]"},
      {"--split a1=0 --split a1=1", "'a1' is cut twice"},
  };
  ExpectRefusedBeforeAnyWork(bad, "--split");
}

TEST_F(CliIo, BadAutoSplitIsNamedBeforeAnyWork) {
  const std::vector<std::pair<std::string, std::string>> bad = {
      {"--auto-split 6", "auto split: 6 rounds; expected 0 (off) to 5"},
      {"--auto-split -1", "expected 0 (off) to 5"},
      {"--auto-split 1 --executor mpi", "not under the mpi executor"},
  };
  ExpectRefusedBeforeAnyWork(bad, "--auto-split");
}

// At order 1 the engine searches no feasible points, so there is nothing to cut beyond: no round runs, and the
// output and the JSON say why (the rounds themselves: box_split_test).
TEST_F(CliIo, AutoSplitSaysWhyNoRoundRan) {
  const auto r = Cli(Bounds("--order 1 --threads 1 --params a1 --auto-split 2 --json " + Path("auto.json")));
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_TRUE(Has(r.output, "automatic cuts: 0 round(s) after the first run (no interval has a range of certified "
                            "feasible points to cut beyond)")) << r.output;
  EXPECT_TRUE(Has(r.output, "round 0 (first run, 1 piece(s)): a1 [")) << r.output;
  nlohmann::json j;
  std::ifstream(Path("auto.json")) >> j;
  ASSERT_EQ(j.at("auto_split").at("rounds").size(), 1u);
  EXPECT_TRUE(j.at("auto_split").at("rounds")[0].at("cut").is_null());
  EXPECT_EQ(j.at("auto_split").at("rounds")[0].at("intervals")[0].at("lower"), j.at("intervals")[0].at("lower").at("value"));
}

TEST_F(CliIo, SplitRunListsItsPiecesAndWritesThemToTheJson) {
  const auto r = Cli(Bounds("--order 1 --threads 1 --params a1,a2 --split a1=-0.5 --json " + Path("split.json")));
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_TRUE(Has(r.output, "the prior box split into 2 pieces")) << r.output;
  EXPECT_TRUE(Has(r.output, "piece 1 (a1 in [-10, -0.5]): ")) << r.output;
  EXPECT_TRUE(Has(r.output, "piece 2 (a1 in [-0.5, 10]): ")) << r.output;
  nlohmann::json j;
  std::ifstream(Path("split.json")) >> j;
  ASSERT_EQ(j.at("pieces").size(), 2u);
  EXPECT_EQ(j.at("pieces")[1].at("prior_box")[4].at("lo").get<double>(), -0.5);
  EXPECT_EQ(j.at("prior_box")[4].at("lo").get<double>(), -10.0);
}

TEST_F(CliIo, SimulateRejectsNegativeNoiseAndUnstableModels) {
  std::ofstream(Path("unstable.json")) << R"({"type": "hammerstein_wiener", "linear": {"a": [-1.1], "b": [0, 1]}})";
  const auto neg = Cli("simulate --model " + Path("unstable.json") + " --input " + Path("rec.csv") +
                       " --noise-bound -1 --allow-unstable --out " + Path("sim.csv"));
  EXPECT_NE(neg.code, 0) << neg.output;
  EXPECT_FALSE(fs::exists(Path("sim.csv")));
  const auto unstable = Cli("simulate --model " + Path("unstable.json") + " --input " + Path("rec.csv") + " --out " +
                            Path("sim.csv"));
  EXPECT_EQ(unstable.code, 2) << unstable.output;
  EXPECT_TRUE(Has(unstable.output, "--allow-unstable")) << unstable.output;
  EXPECT_FALSE(fs::exists(Path("sim.csv")));
  const auto allowed = Cli("simulate --model " + Path("unstable.json") + " --input " + Path("rec.csv") +
                           " --allow-unstable --out " + Path("sim.csv"));
  EXPECT_EQ(allowed.code, 0) << allowed.output;
  EXPECT_TRUE(fs::exists(Path("sim.csv")));
  const auto example = Cli("simulate --example cerone2011 --noise-bound 0.3 --out " + Path("ex.csv"));
  EXPECT_NE(example.code, 0) << "the example's own noise would silently win: " << example.output;
}

TEST_F(CliIo, JsonPathIsCheckedBeforeAnyWork) {
  fs::create_directories(Path("adir"));
  for (const std::string& bad : {Path("adir"), std::string("/nonexistent/x.json")}) {
    const auto r = Cli(Bounds("--json " + bad));
    EXPECT_EQ(r.code, 2) << r.output;
    EXPECT_TRUE(Has(r.output, "--json")) << r.output;
    EXPECT_FALSE(Has(r.output, "orthants:")) << "the computation ran first: " << r.output;
  }
  EXPECT_FALSE(fs::exists(Path("adir.tmp")));
  const auto run_dir = Cli(Bounds("--run-dir " + Path("rec.csv")));
  EXPECT_EQ(run_dir.code, 2) << run_dir.output;
}

TEST_F(CliIo, FailingEsmaeilaniWritesNoModel) {
  // A recording the estimator handles; first show that the command succeeds with a valid validation file.
  CsvTable t;
  std::vector<double> u, y;
  double z = 0.0, x_prev = 0.0;
  for (int k = 0; k < 300; ++k) {
    const double level = std::sin(0.37 * (k / 5)) * 0.9;
    u.push_back(level);
    z = 0.6 * z + 0.4 * x_prev;
    x_prev = level + 0.2 * level * level * level;
    y.push_back(z + 0.1 * z * z * z);
  }
  t.add_column("u", u);
  t.add_column("y", y);
  write_csv(Path("seg.csv"), t);
  std::ofstream(Path("bad.csv")) << "u,y\n1,2\n3,oops\n";
  // f pinned at two points, g^-1 with a positive slope: the normalisation the estimator requires.
  std::ofstream(Path("c.json")) << R"({"f": {"points": [[0, 0], [0.9, 1.0458]]}, "g_inverse": {"slopes": [{"min": 0.2}]}})";
  const std::string common = "esmaeilani --order 1 --grid-f 6 --grid-g 6 --data " + Path("seg.csv") + " --constraints " +
                             Path("c.json") + " --out " + Path("m.json");
  const auto good = Cli(common + " --validate " + Path("seg.csv"));
  ASSERT_EQ(good.code, 0) << good.output;
  ASSERT_TRUE(fs::exists(Path("m.json")));
  fs::remove(Path("m.json"));
  const auto bad = Cli(common + " --validate " + Path("bad.csv"));
  EXPECT_EQ(bad.code, 2) << bad.output;
  EXPECT_TRUE(Has(bad.output, "bad.csv:3")) << bad.output;
  EXPECT_FALSE(fs::exists(Path("m.json"))) << "a failing command wrote its result";
}

TEST_F(CliIo, PopExportIsCheckedFirstAndWrittenOnlyOnSuccess) {
  const std::string problem = std::string(HW_SOURCE_DIR) + "/paper_examples/problems/gloptipoly_constrained.json";
  const auto r = Cli("pop " + problem + " --export /nonexistent/p.dat-s");
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_FALSE(Has(r.output, "bound:")) << r.output;
  const auto ok = Cli("pop " + problem + " --export " + Path("p.dat-s"));
  EXPECT_EQ(ok.code, 0) << ok.output;
  EXPECT_TRUE(fs::exists(Path("p.dat-s")));
}

TEST_F(CliIo, ScenarioWritesAllThreeFilesOrNone) {
  const auto bad = Cli("scenario --hidden-effect none --samples 200 --out " + Path("missing_dir/s"));
  EXPECT_EQ(bad.code, 2) << bad.output;
  const auto ok = Cli("scenario --hidden-effect none --samples 200 --out " + Path("s"));
  EXPECT_EQ(ok.code, 0) << ok.output;
  for (const char* f : {"s_ident.csv", "s_valid.csv", "s_truth.json"}) EXPECT_TRUE(fs::exists(Path(f))) << f;
  for (const auto& e : fs::directory_iterator(dir_)) EXPECT_NE(e.path().extension(), ".tmp") << e.path();
}

TEST_F(CliIo, HugePopOrderIsRefusedWithItsNumbers) {
  std::ofstream(Path("p.json")) << R"({"variables":["x1"],"minimize":"x1","constraints":["x1 >= 4","x1 <= 9"]})";
  std::ofstream(Path("p3.json")) << R"({"variables":["x1","x2","x3"],"minimize":"x1","constraints":["x1 >= 4"]})";
  const auto r = Cli("pop " + Path("p3.json") + " --order 1000");
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_TRUE(Has(r.output, "moments")) << r.output;
  EXPECT_TRUE(Has(r.output, "memory available")) << r.output;
  EXPECT_TRUE(Has(r.output, "largest order that fits")) << r.output;
  EXPECT_LT(r.seconds, 10.0) << "the refusal must come before any allocation";
  const auto small = Cli("pop " + Path("p.json") + " --order 3");
  EXPECT_EQ(small.code, 0) << small.output;
}

TEST_F(CliIo, DirectoryAsInputFileIsNamed) {
  fs::create_directories(Path("recdir"));
  const auto r = Cli("bounds --data " + Path("recdir") + " --noise-bound 0.1 --quiet");
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_TRUE(Has(r.output, Path("recdir") + ": is a directory")) << r.output;
  const auto m = Cli("simulate --model " + Path("recdir") + " --input " + Path("rec.csv") + " --out " + Path("o.csv"));
  EXPECT_TRUE(Has(m.output, "is a directory")) << m.output;
  // The diagnosis's model reader and the .mat reader name the directory too.
  const auto d = Cli("diagnose --data " + Path("rec.csv") + " --validate " + Path("rec.csv") + " --model " +
                     Path("recdir") + " --out " + Path("diag_out"));
  EXPECT_EQ(d.code, 2) << d.output;
  EXPECT_TRUE(Has(d.output, Path("recdir") + ": is a directory")) << d.output;
  fs::create_directories(Path("matdir.mat"));
  const auto mat = Cli("bounds --data " + Path("matdir.mat") + ":u=u,y=y --noise-bound 0.1 --quiet");
  EXPECT_EQ(mat.code, 2) << mat.output;
  EXPECT_TRUE(Has(mat.output, Path("matdir.mat") + ": is a directory")) << mat.output;
}

TEST_F(CliIo, NegativeNoiseBoundNamesTheFileLine) {
  CsvTable t = read_csv(Path("rec.csv"));
  t.columns[2][9] = -0.5;  // data row 10 = file line 11
  write_csv(Path("neg.csv"), t);
  const auto r = Cli("bounds --data " + Path("neg.csv") + " --noise-col noise_bound --horizon 1 --quiet");
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_TRUE(Has(r.output, "neg.csv:11")) << r.output;
}

// A run without --verbose shows its phases, not the constraint-generation rounds of every job (hundreds of lines
// on the bundled example); --verbose shows them. Output to a pipe: plain progress lines.
TEST_F(CliIo, RoundLinesOnlyWithVerbose) {
  const std::string run = "bounds --data " + Path("rec.csv") + " --noise-col noise_bound --horizon 1 --order 1 --threads 1 --params a1";
  const auto plain = Cli(run);
  ASSERT_EQ(plain.code, 0) << plain.output;
  EXPECT_TRUE(Has(plain.output, "[LP screen of orthants] ")) << plain.output;
  EXPECT_FALSE(Has(plain.output, "] round 1:")) << plain.output;
  EXPECT_FALSE(Has(plain.output, "\r")) << "a pipe gets no in-place updates: " << plain.output;
  EXPECT_LE(std::count(plain.output.begin(), plain.output.end(), '\n'), 40) << plain.output;
  const auto verbose = Cli(run + " --verbose");
  ASSERT_EQ(verbose.code, 0) << verbose.output;
  EXPECT_TRUE(Has(verbose.output, "] round 1:")) << verbose.output;
  const auto quiet = Cli(run + " --quiet");
  EXPECT_FALSE(Has(quiet.output, "[LP screen of orthants]")) << quiet.output;
  EXPECT_NE(Cli(run + " --quiet --verbose").code, 0);
}

// On a terminal each phase is one line rewritten in place (run under script(1), which gives it a terminal).
TEST_F(CliIo, TerminalGetsOneLivePhaseLine) {
  if (std::system("command -v script > /dev/null 2>&1") != 0) GTEST_SKIP() << "script(1) is not installed";
  const std::string run = std::string(HW_CLI_PATH) + " bounds --data " + Path("rec.csv") +
                          " --noise-col noise_bound --horizon 1 --order 1 --threads 1 --params a1";
  const auto r = testing_support::RunCommand("script -qec '" + run + "' /dev/null 2>&1");
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_TRUE(Has(r.output, "\r\033[K[LP screen of orthants] ")) << r.output;
  EXPECT_FALSE(Has(r.output, "] round 1:")) << r.output;
}

TEST_F(CliIo, PlotWritesAPng) {
  const auto r = Cli(Bounds("--order 1 --threads 1 --params a1,a2 --plot " + Path("bounds.png") +
                            " --truth 0.4,-0.1,0.8,3.2,1.8,0.9,1.6,2.1"));
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_TRUE(Has(r.output, "wrote " + Path("bounds.png"))) << r.output;
  std::ifstream in(Path("bounds.png"), std::ios::binary);
  std::string magic(8, '\0');
  in.read(magic.data(), 8);
  EXPECT_EQ(magic, std::string("\x89PNG\r\n\x1a\n", 8));
  EXPECT_FALSE(fs::exists(Path("bounds.png.tmp")));
}

// --plot is checked before any work: a name that is not .png, and no gnuplot on the PATH.
TEST_F(CliIo, PlotWithoutGnuplotIsRefusedBeforeAnyWork) {
  const auto jpg = Cli(Bounds("--order 1 --plot " + Path("bounds.jpg")));
  EXPECT_EQ(jpg.code, 2) << jpg.output;
  EXPECT_TRUE(Has(jpg.output, "ending in .png")) << jpg.output;
  fs::create_directories(Path("empty_bin"));
  const auto r = testing_support::RunCommand("PATH=" + Path("empty_bin") + " " + HW_CLI_PATH + " " +
                                             Bounds("--order 1 --plot " + Path("bounds.png")) + " 2>&1");
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_TRUE(Has(r.output, "gnuplot is not on the PATH")) << r.output;
  EXPECT_FALSE(Has(r.output, "orthants:")) << "it ran: " << r.output;
  EXPECT_FALSE(fs::exists(Path("bounds.png")));
}

TEST_F(CliIo, HelpShowsDefaultsAndTheVerifyPair) {
  const auto r = Cli("bounds --help");
  EXPECT_EQ(r.code, 0);
  EXPECT_FALSE(Has(r.output, "{false}")) << r.output;
  EXPECT_TRUE(Has(r.output, "--no-verify")) << r.output;
  EXPECT_TRUE(Has(r.output, "TEXT=poly:3")) << r.output;  // --input-basis
  EXPECT_TRUE(Has(r.output, "=minimal")) << r.output;     // --order
  EXPECT_TRUE(Has(r.output, "=auto")) << r.output;        // --solver
  EXPECT_TRUE(Has(r.output, "Exit status")) << r.output;
  EXPECT_TRUE(Has(r.output, "3 model invalidated")) << r.output;
  const auto both = Cli(Bounds("--verify --no-verify"));
  EXPECT_NE(both.code, 0) << both.output;
  const auto sim = Cli("simulate --help");
  EXPECT_TRUE(Has(sim.output, "=1000")) << sim.output;  // --samples
}

}  // namespace
}  // namespace hw
#endif
