// Recordings whose numbers the constraints cannot carry are errors naming the sample's file line (issue
// item 3), and the CSV reader's edge cases say what is wrong where (item 9).
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "core/cerone_example.hpp"
#include "core/csv_table.hpp"
#include "dss/hw_outer_set.hpp"
#include "tests/test_support.hpp"

namespace hw {
namespace {

using testing_support::ErrorOf;
using testing_support::Has;

// A small recording of the paper's example with data rows on file lines 2.. (a header on line 1).
dss::HwData Recording(int samples) {
  const auto ex = SimulateCeroneExample(3, samples);
  dss::HwData d;
  d.u = ex.u;
  d.y = ex.y;
  d.noise_bound.assign(ex.y.size(), ex.noise_bound);
  d.source = "rec.csv";
  for (int t = 0; t < samples; ++t) d.lines.push_back(t + 2);
  return d;
}

dss::HwOuterSet Set(const dss::HwData& d) {
  return dss::HwOuterSet(dss::CeroneExampleStructure(), d, 1,
                           std::vector<std::pair<double, double>>(8, {-10.0, 10.0}));
}

TEST(OverflowingData, OutputWhoseCubeOverflowsNamesTheLine) {
  auto d = Recording(30);
  d.y[11] = 1e104;  // y^3 = inf with poly:3
  const std::string e = ErrorOf([&] { Set(d); });
  EXPECT_TRUE(Has(e, "rec.csv:13")) << e;
  EXPECT_TRUE(Has(e, "overflows")) << e;
  EXPECT_TRUE(Has(e, "rescale column y")) << e;
}

TEST(OverflowingData, InputWhoseCubeOverflowsNamesTheLine) {
  auto d = Recording(30);
  d.u[20] = 1e104;
  const std::string e = ErrorOf([&] { Set(d); });
  EXPECT_TRUE(Has(e, "rec.csv:22")) << e;
  EXPECT_TRUE(Has(e, "rescale column u")) << e;
}

TEST(OverflowingData, ProductsThatOverflowAreCaughtBeforeAnySolve) {
  auto d = Recording(30);
  for (double& u : d.u) u *= 5e101;  // u^3 < 1e308 is finite; times the box radii it is not
  const std::string e = ErrorOf([&] { Set(d); });
  EXPECT_TRUE(Has(e, "rec.csv:")) << e;
  EXPECT_TRUE(Has(e, "overflow")) << e;
}

TEST(PrecisionLoss, LargeInputGetsAWarningWithTheScaling) {
  EXPECT_TRUE(Set(Recording(30)).warnings().empty());
  auto d = Recording(30);
  for (double& u : d.u) u *= 1e5;  // basis values u .. u^3 span 1e11
  const auto set = Set(d);
  ASSERT_EQ(set.warnings().size(), 1u);
  EXPECT_TRUE(Has(set.warnings()[0], "divide column u by 1e+06")) << set.warnings()[0];
}

TEST(PrecisionLoss, NoiseBelowTheResolutionOfYIsReported) {
  auto d = Recording(30);
  for (double& y : d.y) y += 1e17;  // y + 0.16 == y
  const auto set = Set(d);
  bool found = false;
  for (const auto& w : set.warnings()) found = found || Has(w, "below the resolution of y");
  EXPECT_TRUE(found);
}

TEST(NoiseBound, NegativeValueNamesTheFileLine) {
  auto d = Recording(30);
  d.noise_bound[6] = -0.1;
  const std::string e = ErrorOf([&] { Set(d); });
  EXPECT_TRUE(Has(e, "rec.csv:8")) << e;
}

TEST(CsvEdgeCases, DirectoryIsNamedAsADirectory) {
  const std::string dir = ::testing::TempDir() + "/a_directory.csv";
  std::filesystem::create_directories(dir);
  const std::string e = ErrorOf([&] { read_csv(dir); });
  EXPECT_TRUE(Has(e, dir)) << e;
  EXPECT_TRUE(Has(e, "is a directory")) << e;
  const std::string missing = ErrorOf([&] { read_csv(dir + "/none.csv"); });
  EXPECT_TRUE(Has(missing, "no such file")) << missing;
}

TEST(CsvEdgeCases, DuplicateColumnNamesAreAnError) {
  const std::string e = ErrorOf([&] { parse_csv("t,u,y,u\n0,1,2,3\n", "d.csv"); });
  EXPECT_TRUE(Has(e, "d.csv:1")) << e;
  EXPECT_TRUE(Has(e, "'u' twice (columns 2 and 4)")) << e;
}

TEST(CsvEdgeCases, ShortRowCountsItsCells) {
  const std::string e = ErrorOf([&] { parse_csv("# c\nt,u,y\n0,1,2\n1,2\n", "d.csv"); });
  EXPECT_TRUE(Has(e, "d.csv:4: 2 cells but the header has 3 columns")) << e;
  // An explicitly empty cell is still named by its column.
  const std::string empty = ErrorOf([&] { parse_csv("t,u,y\n0,,2\n", "d.csv"); });
  EXPECT_TRUE(Has(empty, "column 'u' is empty")) << empty;
  EXPECT_EQ(parse_csv("t,u,y\n0,1,2\n1,2\n", "d.csv", true).column("y").size(), 2u);  // NaN allowed
}

TEST(CsvEdgeCases, ByteOrderMarkAndLineNumbers) {
  const auto t = parse_csv("\xEF\xBB\xBFt,u\n# c\n0,1\n\n1,2\n", "d.csv");
  EXPECT_TRUE(t.has("t"));
  EXPECT_EQ(t.lines, (std::vector<int>{3, 5}));
}

}  // namespace
}  // namespace hw
