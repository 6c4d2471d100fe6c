// Result files: paths checked before work, written together and only on success, no stray .tmp (issue
// item 7); what a person reads is rendered as meant (item 13: Markdown cells, gnuplot labels, the
// set-membership midpoint curve explained).
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "compare/scenario.hpp"
#include "compare/study.hpp"
#include "core/atomic_write.hpp"
#include "core/input_error.hpp"
#include "core/output_files.hpp"

namespace hw {
namespace {

namespace fs = std::filesystem;

bool Has(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

fs::path Fresh(const std::string& name) {
  const fs::path d = fs::path(::testing::TempDir()) / name;
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

TEST(OutputPaths, DirectoriesAndMissingParentsAreRejectedUpFront) {
  const auto d = Fresh("outputs_paths");
  EXPECT_NO_THROW(CheckOutputFile((d / "r.json").string(), "--json"));
  EXPECT_THROW(CheckOutputFile(d.string(), "--json"), InputError);
  EXPECT_THROW(CheckOutputFile((d / "missing" / "r.json").string(), "--json"), InputError);
  EXPECT_NO_THROW(CheckOutputDirectory((d / "new" / "deeper").string(), "--out"));
  std::ofstream(d / "file") << "x";
  EXPECT_THROW(CheckOutputDirectory((d / "file").string(), "--out"), InputError);
  EXPECT_THROW(CheckOutputDirectory((d / "file" / "sub").string(), "--out"), InputError);
}

TEST(OutputPaths, FailedAtomicWriteLeavesNoTemporary) {
  const auto d = Fresh("outputs_atomic");
  fs::create_directories(d / "adir");
  EXPECT_THROW(write_text_atomic((d / "adir").string(), "{}"), std::runtime_error);
  EXPECT_FALSE(fs::exists(d / "adir.tmp"));
}

TEST(OutputPaths, OutputFilesCommitAllOrNothing) {
  const auto d = Fresh("outputs_commit");
  OutputFiles ok;
  ok.Add((d / "a.txt").string(), "a");
  ok.Add((d / "b.txt").string(), "b");
  ok.Commit();
  EXPECT_TRUE(fs::exists(d / "a.txt") && fs::exists(d / "b.txt"));
  OutputFiles bad;
  bad.Add((d / "c.txt").string(), "c");
  bad.Add((d / "missing" / "d.txt").string(), "d");
  EXPECT_THROW(bad.Commit(), std::runtime_error);
  EXPECT_FALSE(fs::exists(d / "c.txt"));
  for (const auto& e : fs::directory_iterator(d)) EXPECT_NE(e.path().extension(), ".tmp") << e.path();
}

// Every row of every Markdown table has as many unescaped '|' as its header row.
void ExpectWellFormedTables(const std::string& md) {
  std::istringstream in(md);
  std::string line;
  int columns = -1;
  auto bars = [](const std::string& l) {
    int n = 0;
    for (std::size_t i = 0; i < l.size(); ++i) n += l[i] == '|' && (i == 0 || l[i - 1] != '\\');
    return n;
  };
  while (std::getline(in, line)) {
    if (line.empty() || line[0] != '|') {
      columns = -1;
      continue;
    }
    if (columns < 0) columns = bars(line);
    EXPECT_EQ(bars(line), columns) << line;
  }
}

TEST(ReadableOutputs, SummaryTablesEscapeBars) {
  nlohmann::json s = {{"scenario", "x"}, {"description", "d"}, {"runs", 1}, {"methods", nlohmann::json::object()}};
  s["methods"]["brouri"] = {
      {"applicable", true}, {"runs_ok", 1}, {"failures", nlohmann::json::array()},
      {"quantities", {{"freq_max_error", {{"n", 1}, {"mean", 0.1}, {"std", 0.0}, {"worst", 0.1}}}}}};
  s["methods"]["setmembership"] = {{"applicable", false}, {"reason", "a |reason| with bars"}};
  const std::string md = compare::SummaryMarkdown(s);
  EXPECT_TRUE(Has(md, "normalised \\|G\\| max error")) << md;
  ExpectWellFormedTables(md);
}

TEST(ReadableOutputs, PlotLabelsAndTheMidpointCurveAreExplained) {
  const auto d = Fresh("outputs_plots");
  const auto scenario = compare::LoadScenario("setmembership-example");
  nlohmann::json run = {{"run", 0}, {"methods", nlohmann::json::object()}};
  run["methods"]["setmembership"] = {
      {"applicable", true},
      {"curves", {{"static_u", {-1.0, 0.0, 1.0}}, {"static_y", {0.0, 0.0, 0.0}}, {"omega", {0.1, 1.0}}, {"gain", {1.0, 1.0}}}},
      {"quantities", {{"static_rms_pct", 50.0}}}};
  nlohmann::json summary = {{"methods", nlohmann::json::object()}};
  summary["methods"]["setmembership"] = {
      {"applicable", true}, {"runs_ok", 1}, {"failures", nlohmann::json::array()},
      {"quantities", {{"static_rms_pct", {{"n", 1}, {"mean", 50.0}, {"std", 0.0}, {"worst", 50.0}}}}}};
  compare::WritePlots(d.string(), scenario, {run}, summary);
  std::ifstream in(d / "plots" / "plots.gp");
  std::stringstream gp;
  gp << in.rdbuf();
  EXPECT_TRUE(Has(gp.str(), "y_{ss}")) << gp.str();
  EXPECT_FALSE(Has(gp.str(), "y_ss")) << gp.str();
  EXPECT_TRUE(Has(gp.str(), "interval centres")) << gp.str();
  EXPECT_TRUE(Has(compare::SummaryMarkdown(summary), "centres of its guaranteed intervals"));
}

}  // namespace
}  // namespace hw
