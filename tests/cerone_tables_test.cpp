// The Tables I-III harness (paper_examples/cerone): its end-to-end run on a small example holds every property,
// its JSON has the fields the tables promise, its property checker reports each kind of broken property (so the
// check can fail), the equivalent-SNR bisection finds a known crossing, and the command line rejects bad values.
#include <cmath>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "core/cerone_example.hpp"
#include "dss/edge_witness.hpp"
#include "paper_examples/cerone/equivalent_snr.hpp"
#include "paper_examples/cerone/table_properties.hpp"
#include "paper_examples/cerone/tables_cli.hpp"
#include "paper_examples/cerone/tables_report.hpp"
#include "paper_examples/cerone/tables_run.hpp"

namespace hw::cerone {
namespace {

const Log kQuiet = [](const std::string&) {};

// N = 50, n = 1, order 1 (each relaxation takes milliseconds), two parameters, one realisation.
TablesOptions SmallOptions() {
  TablesOptions o;
  o.horizons = {1};
  o.orders = o.outer_orders = {1};
  o.snrs = o.outer_snrs = {31};
  o.seeds = {1};
  o.samples = 50;
  o.params = {"a1", "b1"};
  o.inner.random_starts = 1;
  o.bounds.solver = "csdp";
  o.bounds.threads = 1;
  return o;
}

TEST(CeroneTables, SmallRunHoldsEveryPropertyAndWritesTheFields) {
  const TablesOptions options = SmallOptions();
  std::string error;
  ASSERT_TRUE(options.IsValid(&error)) << error;
  TablesReport report;
  report.options = options;
  report.cases = RunTables(options, kQuiet);
  ASSERT_EQ(report.cases.size(), 1u);
  report.violations = CheckTableProperties(report.cases, options.tolerance);
  EXPECT_TRUE(report.violations.empty()) << report.violations.front().text;

  const TableCase& c = report.cases.front();
  const auto ex = SimulateCeroneExample(1, 50, 31);
  const auto set = ExampleSet(ex, 1, options.box);
  ASSERT_EQ(c.inner.intervals.size(), 2u);
  ASSERT_TRUE(c.outer.count(1));
  for (const auto& inner : c.inner.intervals) {
    ASSERT_TRUE(inner.found) << inner.name;
    const auto* outer = FindInterval(c.outer.at(1), inner.name);
    ASSERT_NE(outer, nullptr);
    EXPECT_LE(outer->lower.value, inner.lower) << inner.name;
    EXPECT_GE(outer->upper.value, inner.upper) << inner.name;
    for (const auto* w : {&inner.lower_witness, &inner.upper_witness}) {  // re-certified here, independently
      EXPECT_GE(dss::CertifiedMinSlack(set, w->orthant, w->point), 0.0) << inner.name;
      EXPECT_EQ(set.orthant_of(w->point), w->orthant);
    }
  }
  const auto json = TablesJson(report);
  EXPECT_TRUE(json.at("properties_hold").get<bool>());
  const auto& row = json.at("cases").at(0).at("rows").at(0);
  for (const char* key : {"parameter", "truth", "paper", "inner", "outer", "inner_reaches_box"})
    EXPECT_TRUE(row.contains(key)) << key;
  for (const char* key : {"lower", "upper", "half_width", "lower_witness", "upper_witness"})
    EXPECT_TRUE(row.at("inner").contains(key)) << key;
  for (const char* key : {"lower", "upper", "half_width", "ratio_outer_inner", "ratio_outer_paper", "lower_status"})
    EXPECT_TRUE(row.at("outer").at("1").contains(key)) << key;
  EXPECT_TRUE(row.at("inner").at("lower_witness").contains("certified_slack"));
  EXPECT_NE(TablesMarkdown(report).find("Every property holds"), std::string::npos);
  const auto plots = TablesPlots(report);
  ASSERT_EQ(plots.size(), 1u);
  EXPECT_EQ(plots.front().stem, "intervals_snr31_seed1");
}

// n = 1 then n = 2 of one realisation: the longer horizon's outer runs start in the box of the shorter one's
// outer intervals, and that box holds every certified point of D^ss(2) the inner hull finds (the premise:
// D^ss(2) lies inside D^ss(1)). Outer runs at n = 1 only (order 1, milliseconds per job).
TEST(CeroneTables, LongerHorizonStartsInTheShorterOnesOuterBox) {
  TablesOptions options = SmallOptions();
  options.horizons = {2, 1};  // run in ascending order whatever the list's order
  options.orders = {1, 2};
  options.outer_orders = {1};
  const auto cases = RunTables(options, kQuiet);
  ASSERT_EQ(cases.size(), 2u);
  ASSERT_EQ(cases[0].horizon, 1);
  ASSERT_EQ(cases[1].horizon, 2);
  ASSERT_TRUE(cases[0].outer.count(1));
  EXPECT_EQ(cases[0].box_from_horizon, 0);
  EXPECT_EQ(cases[1].box_from_horizon, 1);
  const auto box = OuterIntervalBox(cases[0]);
  ASSERT_EQ(cases[1].outer_box, box);
  int shrunk = 0;
  for (std::size_t k = 0; k < box.size(); ++k) shrunk += box[k].second - box[k].first < 2 * options.box - 1e-6;
  EXPECT_GE(shrunk, 1);  // a1 at least (at N = 50 the n = 1 interval of b1 may reach the prior box)
  for (const auto& inner : cases[1].inner.intervals) {
    ASSERT_TRUE(inner.found) << inner.name;
    const auto k = std::find(cases[1].names.begin(), cases[1].names.end(), inner.name) - cases[1].names.begin();
    EXPECT_LE(box[k].first, inner.lower) << inner.name;
    EXPECT_GE(box[k].second, inner.upper) << inner.name;
  }
  options.nest_horizons = false;
  const auto separate = RunTables(options, kQuiet);
  EXPECT_EQ(separate[1].box_from_horizon, 0);
  const std::vector<std::pair<double, double>> prior(8, {-options.box, options.box});
  EXPECT_EQ(separate[1].outer_box, prior);
}

TEST(CeroneTables, OuterIntervalBoxIntersectsEveryRunWithTheStartingBox) {
  TableCase c;
  c.names = {"a1", "b1"};
  c.outer_box = {{-10, 10}, {-1, 1}};
  dss::ParameterInterval a1, b1, a1_tighter;
  a1.name = a1_tighter.name = "a1", b1.name = "b1";
  a1.lower.value = -2, a1.upper.value = 3;
  a1_tighter.lower.value = -1, a1_tighter.upper.value = 5;
  b1.lower.value = -4, b1.upper.value = 0.5;
  c.outer[2].intervals = {a1, b1};
  c.outer[3].intervals = {a1_tighter};
  const auto box = OuterIntervalBox(c);
  EXPECT_NEAR(box[0].first, -1, 1e-8);
  EXPECT_NEAR(box[0].second, 3, 1e-8);
  EXPECT_LT(box[0].first, -1);  // widened outward, never inward
  EXPECT_GT(box[0].second, 3);
  EXPECT_NEAR(box[1].first, -1, 1e-8);
  EXPECT_NEAR(box[1].second, 0.5, 1e-8);
}

// A synthetic interval for the checker.
dss::ParameterInterval Iv(const std::string& name, double lo, double hi) {
  dss::ParameterInterval iv;
  iv.name = name;
  iv.lower.value = lo;
  iv.upper.value = hi;
  return iv;
}

TableCase SyntheticCase(int horizon, std::map<int, std::pair<double, double>> outer, double inner_lo, double inner_hi) {
  TableCase c;
  c.horizon = horizon;
  c.names = {"a1"};
  c.truth = {1.8};
  InnerInterval inner;
  inner.name = "a1";
  inner.found = true;
  inner.lower = inner_lo;
  inner.upper = inner_hi;
  c.inner.intervals = {inner};
  for (const auto& [order, iv] : outer) c.outer[order].intervals = {Iv("a1", iv.first, iv.second)};
  return c;
}

std::vector<std::string> Properties(const std::vector<TableCase>& cases) {
  std::vector<std::string> kinds;
  for (const auto& v : CheckTableProperties(cases, 1e-6)) kinds.push_back(v.property);
  return kinds;
}

TEST(CeroneTables, EachBrokenPropertyIsReported) {
  using Kinds = std::vector<std::string>;
  // Nested as they must be: order 3 inside order 2, n = 3 inside n = 2, witnesses and truth inside.
  const auto n2 = SyntheticCase(2, {{2, {1.0, 3.0}}, {3, {1.2, 2.8}}}, 1.5, 2.5);
  const auto n3 = SyntheticCase(3, {{2, {1.1, 2.9}}, {3, {1.3, 2.7}}}, 1.6, 2.4);
  EXPECT_EQ(Properties({n2, n3}), Kinds{});
  // Within the tolerance (verified endpoints rounded outward): still holds.
  EXPECT_EQ(Properties({SyntheticCase(2, {{2, {1.0, 3.0}}, {3, {1.0 - 1e-7, 3.0}}}, 1.5, 3.0 + 1e-7)}), Kinds{});
  // An outer interval that excludes the truth.
  EXPECT_EQ(Properties({SyntheticCase(2, {{2, {1.9, 3.0}}}, 1.95, 2.5)}), Kinds{"truth"});
  // Order 3 wider than order 2.
  EXPECT_EQ(Properties({SyntheticCase(2, {{2, {1.0, 3.0}}, {3, {1.0, 3.1}}}, 1.5, 2.5)}), Kinds{"order"});
  // n = 3 wider than n = 2 at the same order.
  EXPECT_EQ(Properties({SyntheticCase(2, {{2, {1.0, 3.0}}}, 1.5, 2.5), SyntheticCase(3, {{2, {0.9, 2.9}}}, 1.5, 2.5)}),
            Kinds{"horizon"});
  // A witness outside an outer interval of its own horizon ...
  EXPECT_EQ(Properties({SyntheticCase(2, {{2, {1.0, 3.0}}}, 1.5, 3.2)}), Kinds{"witness"});
  // ... and a witness of D^ss(3) outside an outer interval of D^ss(2) (D^ss(3) ⊆ D^ss(2)).
  EXPECT_EQ(Properties({SyntheticCase(2, {{2, {1.0, 3.0}}}, 1.5, 2.5), SyntheticCase(3, {}, 0.5, 2.5)}),
            Kinds{"witness"});
  // A witness of D^ss(2) need not lie in D^ss(3)'s interval: no violation.
  EXPECT_EQ(Properties({SyntheticCase(2, {}, 0.5, 2.5), SyntheticCase(3, {{2, {1.0, 3.0}}}, 1.5, 2.5)}), Kinds{});
  // Different realisations are never compared.
  auto other = SyntheticCase(3, {{2, {0.0, 4.0}}}, 1.5, 2.5);
  other.seed = 2;
  EXPECT_EQ(Properties({SyntheticCase(2, {{2, {1.0, 3.0}}}, 1.5, 2.5), other}), Kinds{});
}

TEST(CeroneTables, EquivalentSnrBisectionFindsTheCrossing) {
  // Every ratio exp((40 - SNR) / 10): the median log ratio crosses 0 at 40 dB.
  auto ratios_at = [](double snr) {
    std::vector<WidthRatio> r;
    for (const char* name : {"a1", "a2", "b1"}) r.push_back({2, name, std::exp((40 - snr) / 10), 1.0});
    return r;
  };
  EquivalentSnrOptions options;
  options.iterations = 8;
  const auto found = FindEquivalentSnr(options, ratios_at);
  EXPECT_TRUE(found.bracketed);
  EXPECT_NEAR(found.best.snr_db, 40.0, (60.0 - 31.0) / 256 + 1e-9);
  EXPECT_EQ(found.evaluations.size(), 10u);
  options.low_db = 45;  // the crossing is below the range: reported as not bracketed, the low end closest
  const auto outside = FindEquivalentSnr(options, ratios_at);
  EXPECT_FALSE(outside.bracketed);
  EXPECT_EQ(outside.best.snr_db, 45.0);
  EXPECT_TRUE(outside.to_json().contains("criterion"));
}

TEST(CeroneTables, EquivalentSnrReportsEachTablesOwnCriterion) {
  // n = 2 ratios cross 1 at 40 dB, n = 3 ratios at 50 dB: the joint median lies between, each table's own
  // criterion is its own.
  auto ratios_at = [](double snr) {
    std::vector<WidthRatio> r;
    for (const char* name : {"a1", "a2"}) {
      r.push_back({2, name, std::exp((40 - snr) / 10), 1.0});
      r.push_back({3, name, std::exp((50 - snr) / 10), 1.0});
    }
    return r;
  };
  EquivalentSnrOptions options;
  options.iterations = 3;
  const auto found = FindEquivalentSnr(options, ratios_at);
  const SnrEvaluation& first = found.evaluations.front();
  EXPECT_EQ(first.horizons(), (std::vector<int>{2, 3}));
  EXPECT_NEAR(first.criterion_of(2), (40 - 31.0) / 10, 1e-12);
  EXPECT_NEAR(first.criterion_of(3), (50 - 31.0) / 10, 1e-12);
  EXPECT_NEAR(first.criterion, (45 - 31.0) / 10, 1e-12);
  EXPECT_NEAR(found.to_json()["evaluations"][0]["criterion_by_horizon"]["3"].get<double>(), 1.9, 1e-12);
  TablesReport report;
  report.equivalent = found;
  const std::string md = TablesMarkdown(report);
  EXPECT_NE(md.find("| SNR [dB] | criterion | n = 2 only | n = 3 only |\n|---|---|---|---|\n"), std::string::npos);
  EXPECT_NE(md.find("| 31.00 | 1.400 | 0.900 | 1.900 |\n"), std::string::npos) << md;
}

TEST(CeroneTables, InnerHullsNarrowWithLessNoise) {
  TablesOptions options = SmallOptions();
  options.horizons = {2};
  options.samples = 60;
  const auto at31 = InnerWidthRatios(options, 31, 1, kQuiet);
  const auto at60 = InnerWidthRatios(options, 60, 1, kQuiet);
  ASSERT_EQ(at31.size(), 2u);
  ASSERT_EQ(at60.size(), 2u);
  for (std::size_t i = 0; i < at31.size(); ++i) {
    EXPECT_GT(at31[i].ratio(), 0.0) << at31[i].parameter;
    EXPECT_LT(at60[i].ratio(), at31[i].ratio()) << at31[i].parameter;
  }
  EXPECT_LT(MedianLogRatio(at60), MedianLogRatio(at31));
}

// With two tables the evaluation's log line carries each table's own criterion: a bisection stopped before its
// JSON is written still tells where each table stood.
TEST(CeroneTables, EvaluationLogShowsEachTablesOwnCriterion) {
  TablesOptions options = SmallOptions();
  options.horizons = {2, 3};
  options.samples = 60;
  std::string last;
  const auto ratios = InnerWidthRatios(options, 31, 1, [&](const std::string& line) { last = line; });
  const SnrEvaluation evaluation{31, MedianLogRatio(ratios), ratios};
  ASSERT_EQ(evaluation.horizons(), (std::vector<int>{2, 3}));
  EXPECT_EQ(last, fmt::format("equivalent SNR: 31 dB -> median log ratio {:.3f} (n = 2: {:.3f}, n = 3: {:.3f})",
                              evaluation.criterion, evaluation.criterion_of(2), evaluation.criterion_of(3)));
}

// The engine's feasible points enter the inner hull when they certify (the harness passes them as `given`):
// a point from a full local search widens a hull whose own searches stop after one iteration; a point that
// explains nothing is left out.
TEST(CeroneTables, GivenPointsWidenTheInnerHullOnlyWhenTheyCertify) {
  const auto ex = SimulateCeroneExample(1, 50, 31);
  const auto set = ExampleSet(ex, 1, 10.0);
  const auto truth = CeroneExample::TrueParameters();
  const std::vector<int> a1 = ParameterIndices(set, {"a1"});
  ASSERT_EQ(a1.size(), 1u);
  InnerHullOptions short_searches;
  short_searches.random_starts = 0;
  short_searches.restart_rounds = 0;
  short_searches.local.max_iterations = 1;
  const auto far = dss::LocalExtreme(set, set.orthant_of(truth), a1[0], -1, truth);
  ASSERT_TRUE(far.found);
  const InnerHull own = ComputeInnerHull(set, truth, a1, short_searches);
  ASSERT_TRUE(own.intervals[0].found);
  ASSERT_LT(far.value, own.intervals[0].lower - 1e-3) << "the full search must reach beyond the short ones";
  auto nonsense = truth;
  nonsense[a1[0]] = 9.0;
  const InnerHull seeded = ComputeInnerHull(set, truth, a1, short_searches, {far.point, nonsense});
  EXPECT_EQ(seeded.given_witnesses, 1);
  EXPECT_EQ(seeded.intervals[0].lower, far.value);
  EXPECT_EQ(seeded.intervals[0].upper, own.intervals[0].upper);
  EXPECT_GE(dss::CertifiedMinSlack(set, seeded.intervals[0].lower_witness.orthant, seeded.intervals[0].lower_witness.point), 0.0);
}

int Parse(const std::vector<std::string>& args, TablesCommand* command = nullptr) {
  TablesCommand local;
  std::string message;
  return ParseTablesCommand(args, command ? command : &local, &message);
}

TEST(CeroneTables, CommandLineChecksEveryValue) {
  TablesCommand command;
  ASSERT_EQ(Parse({"--orders", "2"}, &command), 0);
  EXPECT_EQ(command.options.orders, std::vector<int>{2});
  EXPECT_EQ(command.options.outer_orders, std::vector<int>{2});
  EXPECT_EQ(command.options.snrs, (std::vector<double>{31, 35, 40, 45}));
  ASSERT_EQ(Parse({"--outer-orders", "none", "--outer-snr", "31", "--row-block-order", "1", "--params", "a1,b2"},
                  &command),
            0);
  EXPECT_TRUE(command.options.outer_orders.empty());
  EXPECT_EQ(command.options.outer_snrs, std::vector<double>{31});
  EXPECT_EQ(command.options.bounds.generation.block_order_cap, 1);
  EXPECT_EQ(command.options.params, (std::vector<std::string>{"a1", "b2"}));
  for (const std::vector<std::string>& bad :
       {std::vector<std::string>{"--bogus"}, {"--orders", "2,x"}, {"--orders", "1"}, {"--solver", "nope"},
        {"--params", "zz"}, {"--outer-orders", "4"}, {"--outer-snr", "50"}, {"--seeds", "-1"}, {"--threads", "-2"},
        {"--samples", "5"}, {"--equivalent-range", "60,31"}, {"--row-block-order", "-3"}, {"--horizons", "0"}})
    EXPECT_EQ(Parse(bad), 2) << bad.front() << " " << (bad.size() > 1 ? bad[1] : "");
}

}  // namespace
}  // namespace hw::cerone
