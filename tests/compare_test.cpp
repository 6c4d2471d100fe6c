// Comparison studies (compare/): scenario adapters against the paper simulators, a small end-to-end study
// whose tables are recomputed from its per-run files, coverage of every guaranteed interval, resume, and
// clear errors for bad scenarios.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "compare/methods.hpp"
#include "compare/study.hpp"
#include "core/cerone_example.hpp"
#include "core/input_error.hpp"

namespace hw::compare {
namespace {

using nlohmann::json;
namespace fs = std::filesystem;

json ReadJson(const std::string& path) {
  std::ifstream in(path);
  EXPECT_TRUE(in.good()) << path;
  return json::parse(in);
}

TEST(CompareScenario, RandomInputRecordReproducesThePaperSimulator) {
  const auto s = LoadScenario("setmembership-example");
  double bound = 0.0;
  const auto r = RandomInputRecord(s.plant, s.input_lo, s.input_hi, 80, 31.0, 0.0, 7, &bound);
  const auto ex = SimulateCeroneExample(7, 80, 31.0);
  ASSERT_EQ(r.y.size(), ex.y.size());
  EXPECT_NEAR(bound, ex.noise_bound, 1e-9 * ex.noise_bound);
  for (std::size_t t = 0; t < r.y.size(); ++t) {
    EXPECT_EQ(r.u[t], ex.u[t]);
    EXPECT_NEAR(r.w[t], ex.w[t], 1e-9) << t;
    EXPECT_NEAR(r.y[t], ex.y[t], 1e-9) << t;
  }
}

TEST(CompareScenario, TruthInSetMembershipParametrisationIsThePapers) {
  const auto c = SetMembershipTruth(LoadScenario("setmembership-example").plant);
  ASSERT_TRUE(c.ok) << c.reason;
  const auto p = CeroneExample::TrueParameters();
  ASSERT_EQ(c.theta.size(), p.size());
  for (std::size_t k = 0; k < p.size(); ++k) EXPECT_NEAR(c.theta[k], p[k], 1e-12) << c.names[k];
  // A rescaled plant (input map x2, inverse output x3) has the same normalised parameters.
  auto s = LoadScenario("setmembership-example");
  for (auto& v : s.plant.model.input.coefficients) v *= 2.0;
  for (auto& v : s.plant.inverse_output) v *= 3.0;
  for (auto& v : s.plant.model.linear.b) v *= 1.5;
  const auto c2 = SetMembershipTruth(s.plant);
  for (std::size_t k = 0; k < p.size(); ++k)
    EXPECT_NEAR(c2.theta[k], c.names[k][0] == 'b' ? p[k] * 1.5 * 2.0 / 3.0 : p[k], 1e-12) << c.names[k];
}

TEST(CompareScenario, MethodsOutsideTheirClassAreReportedNotRun) {
  const auto sm = LoadScenario("setmembership-example");
  EXPECT_TRUE(MethodApplies(sm, "setmembership").applies);
  // The paper's horizon and the lowest order that bounds it: informative intervals, not the prior box.
  EXPECT_EQ(sm.setmembership.horizon, 2);
  EXPECT_EQ(sm.setmembership.order, 2);
  EXPECT_TRUE(MethodApplies(sm, "esmaeilani").applies);
  EXPECT_FALSE(MethodApplies(sm, "brouri").applies);
  const auto br = LoadScenario("brouri-backlash");
  EXPECT_TRUE(MethodApplies(br, "brouri").applies);
  EXPECT_FALSE(MethodApplies(br, "setmembership").applies);
  EXPECT_FALSE(MethodApplies(br, "esmaeilani").applies);
  const auto va = LoadScenario("valve");
  EXPECT_TRUE(MethodApplies(va, "esmaeilani").applies);
  EXPECT_FALSE(MethodApplies(va, "setmembership").applies);
  EXPECT_FALSE(MethodApplies(va, "brouri").applies);
  // A user plant whose output map folds back (w = z - z^3 over the reachable z) fits neither static-map method.
  const auto folded = Scenario::FromJson(nlohmann::json::parse(R"({"name": "folded",
      "model": {"input_nonlinearity": {"kind": "identity"}, "linear": {"a": [-0.5], "b": [0, 1]},
                "output_nonlinearity": {"kind": "polynomial", "coefficients": [1, 0, -1]}},
      "input_range": [-2, 2], "noise": {"bound": 0.01}})"), "folded.json");
  EXPECT_FALSE(MethodApplies(folded, "esmaeilani").applies);
  EXPECT_NE(MethodApplies(folded, "esmaeilani").reason.find("monotone"), std::string::npos);
  EXPECT_FALSE(MethodApplies(folded, "setmembership").applies);
  // The same plant with a monotone output map (w = z + z^3) fits Esmaeilani's class.
  auto monotone = folded;
  monotone.plant.model.output.coefficients = {1, 0, 1};
  EXPECT_TRUE(MethodApplies(monotone, "esmaeilani").applies) << MethodApplies(monotone, "esmaeilani").reason;
  const auto j = RunOne(sm, {"brouri"}, 0, 1);
  EXPECT_FALSE(j["methods"]["brouri"]["applicable"].get<bool>());
  EXPECT_FALSE(j["methods"]["brouri"].contains("seconds"));  // not run
  EXPECT_NE(j["methods"]["brouri"]["reason"].get<std::string>().find("backlash"), std::string::npos);
}

TEST(CompareScenario, BadScenarioFilesAreClearErrors) {
  const std::string dir = ::testing::TempDir() + "/compare_bad";
  fs::create_directories(dir);
  auto expect_error = [&](const std::string& text, const std::string& needle) {
    const std::string path = dir + "/s.json";
    std::ofstream(path) << text;
    try {
      LoadScenario(path);
      ADD_FAILURE() << "no error for " << text;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
    }
  };
  expect_error(R"({"name": "x", "model": {"linear": {"a": [0.5], "b": [0, 1]}}, "setmembrship": {}})", "setmembrship");
  expect_error(R"({"name": "x", "plant": "hw"})", "model");
  expect_error(R"({"name": "x", "model": {"linear": {"a": [0.5], "b": [0, 1]}}, "noise": {"std": 1}})", "bounded");
  expect_error(R"({"name": "x", "model": {"linear": {"a": [0.5], "b": [0, 1]}}, "setmembership": {"horizon": 3}})",
               "minimal order");
  expect_error(R"({"name": "x", "model": {"linear": {"a": [0.5], "b": [0, 1]}}, "setmembership": {"contract_passes": 11}})",
               "contraction_passes 11 is out of range 0..10");
  expect_error("{not json", "not valid JSON");
  {  // contract_passes reaches the scenario and its record (scenario.json decides whether a study resumes)
    const std::string path = dir + "/contract.json";
    std::ofstream(path) << R"({"name": "x", "model": {"linear": {"a": [0.5], "b": [0, 1]}}, "noise": {"bound": 0.1},
                                "setmembership": {"contract_passes": 2}})";
    const auto s = LoadScenario(path);
    EXPECT_EQ(s.setmembership.contract_passes, 2);
    EXPECT_EQ(s.to_json()["setmembership"]["contract_passes"], 2);
  }
  EXPECT_THROW(LoadScenario(dir + "/missing.json"), InputError);
  // The truth outside the prior box is an assumption violation, reported as a failed run with the reason.
  auto s = LoadScenario("setmembership-example");
  s.setmembership.box_half_width = 1.0;  // alpha3 = 3.2 lies outside
  s.setmembership.samples = 20;
  const auto j = RunOne(s, {"setmembership"}, 0, 1);
  EXPECT_EQ(j["methods"]["setmembership"]["status"], "failed");
  EXPECT_NE(j["methods"]["setmembership"]["message"].get<std::string>().find("outside the prior box"), std::string::npos);
}

// Recomputes mean / std / worst from the per-run files.
std::map<std::string, std::vector<double>> Values(const std::vector<json>& runs, const std::string& method) {
  std::map<std::string, std::vector<double>> v;
  for (const auto& r : runs) {
    const auto& m = r["methods"][method];
    if (m.value("status", "") != "ok") continue;
    for (const auto& [q, x] : m["quantities"].items()) v[q].push_back(x.get<double>());
  }
  return v;
}

// Run k's file in the study's run cache (summary.json names the folder: runs/<study key>/jobs).
std::string RunFile(const StudyOptions& o, const json& summary, int k) {
  EXPECT_EQ(summary["run_files"], "runs/" + summary["study_key"].get<std::string>() + "/jobs");
  return fmt::format("{}/{}/run_{:04d}.json", o.out_dir, summary["run_files"].get<std::string>(), k);
}

// The set-membership example made small: n = 1, delta = 1 on 40 samples, seconds per run (the scenario's own
// n = 2, delta = 2: minutes).
Scenario SmallSetMembershipExample() {
  auto s = LoadScenario("setmembership-example");
  s.setmembership.samples = 40;
  s.setmembership.horizon = 1;
  s.setmembership.order = 1;
  s.esmaeilani.samples = 150;
  s.validation.samples = 200;
  return s;
}

// Quiet study options on 2 workers, writing into a fresh folder under the test's temporary directory.
StudyOptions SmallStudy(int runs, std::uint64_t seed, const std::string& folder) {
  StudyOptions o;
  o.runs = runs;
  o.seed = seed;
  o.jobs = 2;
  o.quiet = true;
  o.out_dir = ::testing::TempDir() + "/" + folder;
  fs::remove_all(o.out_dir);
  return o;
}

TEST(CompareStudy, SmallStudyTablesAgreeWithPerRunFilesAndIntervalsCoverTheTruth) {
  const auto s = SmallSetMembershipExample();
  StudyOptions o = SmallStudy(3, 11, "compare_small");
  const auto r = RunStudy(o, s);
  EXPECT_EQ(r.runs_computed, 3);
  for (const char* f : {"summary.md", "summary.json", "scenario.json", "plots/plots.gp"})
    EXPECT_TRUE(fs::exists(o.out_dir + "/" + f)) << f;
  const json summary = ReadJson(o.out_dir + "/summary.json");
  std::vector<json> runs;
  for (int k = 0; k < o.runs; ++k) runs.push_back(ReadJson(RunFile(o, summary, k)));

  // Every applicable method ran in every run; brouri was reported, not run.
  EXPECT_TRUE(summary["all_ok"].get<bool>()) << summary["methods"].dump(1);
  EXPECT_FALSE(summary["methods"]["brouri"]["applicable"].get<bool>());

  // Coverage: every guaranteed interval of every run contains the truth (checked on the files themselves).
  int intervals = 0;
  for (const auto& run : runs) {
    const auto& sm = run["methods"]["setmembership"];
    ASSERT_EQ(sm["status"], "ok") << sm.dump(1);
    const auto truth = CeroneExample::TrueParameters();
    ASSERT_EQ(sm["intervals"].size(), truth.size());
    for (std::size_t k = 0; k < truth.size(); ++k) {
      const auto& iv = sm["intervals"][k];
      EXPECT_LE(iv["lower"].get<double>(), truth[k] + 1e-6 * (1 + std::abs(truth[k]))) << iv.dump();
      EXPECT_GE(iv["upper"].get<double>(), truth[k] - 1e-6 * (1 + std::abs(truth[k]))) << iv.dump();
      EXPECT_TRUE(iv["covered"].get<bool>()) << iv.dump();
      ++intervals;
    }
  }
  EXPECT_TRUE(r.coverage_ok);
  EXPECT_EQ(summary["methods"]["setmembership"]["coverage"]["covered"].get<int>(), intervals);
  EXPECT_EQ(summary["methods"]["setmembership"]["coverage"]["total"].get<int>(), intervals);

  // The tables: summary.json and the numbers printed in summary.md equal statistics recomputed here.
  std::ifstream md_in(o.out_dir + "/summary.md");
  std::stringstream md;
  md << md_in.rdbuf();
  int checked = 0;
  for (const std::string method : {"setmembership", "esmaeilani"}) {
    const auto values = Values(runs, method);
    ASSERT_FALSE(values.empty()) << method;
    for (const auto& [q, v] : values) {
      double mean = 0.0;
      for (double x : v) mean += x / v.size();
      double ss = 0.0;
      for (double x : v) ss += (x - mean) * (x - mean);
      const double sd = v.size() > 1 ? std::sqrt(ss / (v.size() - 1)) : 0.0;
      const double worst = q == "fit_pct" ? *std::min_element(v.begin(), v.end()) : *std::max_element(v.begin(), v.end());
      const auto& st = summary["methods"][method]["quantities"][q];
      EXPECT_EQ(st["n"].get<std::size_t>(), v.size()) << method << " " << q;
      EXPECT_NEAR(st["mean"].get<double>(), mean, 1e-12 * (1 + std::abs(mean))) << method << " " << q;
      EXPECT_NEAR(st["std"].get<double>(), sd, 1e-12 * (1 + sd)) << method << " " << q;
      EXPECT_EQ(st["worst"].get<double>(), worst) << method << " " << q;
      const std::string row_tail =
          fmt::format(" | {} | {:.4g} | {:.4g} | {:.4g} |", v.size(), mean, sd, worst);
      EXPECT_NE(md.str().find("| " + method + " | "), std::string::npos);
      EXPECT_NE(md.str().find(row_tail), std::string::npos) << method << " " << q << " row tail " << row_tail;
      ++checked;
    }
  }
  // 6 at least: with b's intervals equal to the (symmetric) prior box the set-membership midpoint model has
  // G(1) = 0, so its normalised frequency response is reported not available rather than as numbers.
  EXPECT_GE(checked, 6);
  // Time per method equals the per-run times.
  double total = 0.0;
  for (const auto& run : runs) total += run["methods"]["esmaeilani"]["seconds"].get<double>();
  EXPECT_NEAR(summary["methods"]["esmaeilani"]["time"]["total"].get<double>(), total, 1e-9);
  // Point estimates mapped into the set-membership parametrisation were checked for every parameter.
  EXPECT_EQ(summary["methods"]["esmaeilani"]["inside_setmembership_intervals"].size(), 8u);

  // Resume: the same study again computes nothing and reports the same tables.
  const auto r2 = RunStudy(o, s);
  EXPECT_EQ(r2.runs_computed, 0);
  EXPECT_EQ(r2.runs_resumed, 3);
  EXPECT_EQ(r2.summary["methods"].dump(), summary["methods"].dump());

  // A damaged run file is recomputed, never trusted; the other runs resume.
  { std::ofstream(RunFile(o, summary, 1)) << "{\"methods\": "; }
  const auto r3 = RunStudy(o, s);
  EXPECT_EQ(r3.runs_computed, 1);
  EXPECT_EQ(r3.runs_resumed, 2);
  EXPECT_TRUE(r3.coverage_ok);
  EXPECT_EQ(ReadJson(RunFile(o, summary, 1))["methods"]["setmembership"]["intervals"].dump(),
            runs[1]["methods"]["setmembership"]["intervals"].dump());
}

TEST(CompareStudy, TheExactSetIsAMethodInsideTheOuterSetAndAroundTheTruth) {
  const auto s = SmallSetMembershipExample();
  StudyOptions o = SmallStudy(2, 21, "compare_exact");
  o.methods = {"setmembership", "exact"};
  const auto r = RunStudy(o, s);
  EXPECT_TRUE(r.coverage_ok);
  const auto truth = CeroneExample::TrueParameters();
  const json summary = ReadJson(o.out_dir + "/summary.json");
  for (int k = 0; k < o.runs; ++k) {
    const json run = ReadJson(RunFile(o, summary, k));
    const auto& outer = run["methods"]["setmembership"];
    const auto& ex = run["methods"]["exact"];
    ASSERT_EQ(ex["status"], "ok") << ex.dump(1);
    // The assumption is stated (whether the final box alone proves it depends on how wide alpha stays).
    EXPECT_NE(ex["assumption"]["assumption"].get<std::string>().find("increases"), std::string::npos);
    ASSERT_EQ(ex["intervals"].size(), truth.size());
    double exact_width = 0.0, outer_width = 0.0;
    for (std::size_t p = 0; p < truth.size(); ++p) {
      const auto& iv = ex["intervals"][p];
      EXPECT_LE(iv["lower"].get<double>(), truth[p]) << iv.dump();
      EXPECT_GE(iv["upper"].get<double>(), truth[p]) << iv.dump();
      // Stage 2 starts in stage 1's box: never wider.
      EXPECT_GE(iv["lower"].get<double>(), outer["intervals"][p]["lower"].get<double>()) << iv.dump();
      EXPECT_LE(iv["upper"].get<double>(), outer["intervals"][p]["upper"].get<double>()) << iv.dump();
      ASSERT_TRUE(iv.contains("inner")) << iv.dump();
      EXPECT_LE(iv["lower"].get<double>(), iv["inner"][0].get<double>()) << iv.dump();
      EXPECT_GE(iv["upper"].get<double>(), iv["inner"][1].get<double>()) << iv.dump();
      exact_width += iv["width"].get<double>();
      outer_width += outer["intervals"][p]["width"].get<double>();
    }
    EXPECT_LT(exact_width, outer_width) << "the exact set is smaller than D^ss(n)";
  }
  EXPECT_EQ(summary["methods"]["exact"]["coverage"]["covered"].get<int>(), o.runs * static_cast<int>(truth.size()));
  std::ifstream md_in(o.out_dir + "/summary.md");
  std::stringstream md;
  md << md_in.rdbuf();
  EXPECT_NE(md.str().find("Guaranteed intervals (exact)"), std::string::npos) << md.str();
}

}  // namespace
}  // namespace hw::compare
