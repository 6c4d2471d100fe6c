// Tests of the discrepancy diagnosis (diagnose/): effect blocks, refit, residual analysis, and a
// concealed-effect confusion study over 3 scenarios per effect + 3 null scenarios (1500 samples each;
// the larger study with 10 per effect is paper_examples/diagnose_study.cpp).
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>

#include <gtest/gtest.h>

#include "core/csv_table.hpp"
#include "diagnose/diagnose.hpp"
#include "diagnose/effects.hpp"
#include "diagnose/refit.hpp"
#include "diagnose/residual_analysis.hpp"
#include "diagnose/scenario.hpp"
#include "diagnose/study.hpp"

namespace hw::diagnose {
namespace {

TEST(EffectBlocks, BacklashIsAPlayOperator) {
  const std::vector<double> u = {0.0, 0.5, 1.0, 0.9, 0.6, 0.0};
  const auto x = ApplyInputBlock({Effect::kBacklash, Location::kInput, {0.2}}, u);
  const std::vector<double> want = {0.0, 0.3, 0.8, 0.8, 0.8, 0.2};
  for (std::size_t i = 0; i < u.size(); ++i) EXPECT_NEAR(x[i], want[i], 1e-12) << i;
}

TEST(EffectBlocks, RateLimitDelayRelayAndStaticMaps) {
  const std::vector<double> u = {0.0, 1.0, 1.0, 1.0, -1.0};
  const auto r = ApplyInputBlock({Effect::kRateLimit, Location::kInput, {0.4}}, u);
  EXPECT_NEAR(r[1], 0.4, 1e-12);
  EXPECT_NEAR(r[3], 1.0, 1e-12);
  EXPECT_NEAR(r[4], 0.6, 1e-12);
  const auto d = ApplyInputBlock({Effect::kDelay, Location::kInput, {2}}, u);
  EXPECT_EQ(d[3], u[1]);
  EXPECT_EQ(d[4], u[2]);
  const auto h = ApplyInputBlock({Effect::kHysteresis, Location::kInput, {0.5, 0.1}}, {0.0, 0.6, 0.0, -0.4, -0.6, 0.0});
  EXPECT_NEAR(h[2], 0.1, 1e-12);    // relay still on after u fell inside the band
  EXPECT_NEAR(h[3], -0.3, 1e-12);   // still on at -0.4
  EXPECT_NEAR(h[5], -0.1, 1e-12);   // switched off below -0.5
  EXPECT_NEAR(ApplyStaticBlock({Effect::kDeadzone, Location::kInput, {0.3}}, -0.5), -0.2, 1e-12);
  EXPECT_NEAR(ApplyStaticBlock({Effect::kSaturation, Location::kInput, {-HUGE_VAL, 0.7}}, 0.9), 0.7, 1e-12);
  EXPECT_NEAR(ApplyStaticBlock({Effect::kQuantization, Location::kOutput, {0.25}}, 0.3), 0.25, 1e-12);
}

TEST(EffectBlocks, ValidationAndJsonRoundTrip) {
  std::string err;
  EXPECT_FALSE((EffectBlock{Effect::kBacklash, Location::kState, {0.1}}.IsValid(&err)));
  EXPECT_NE(err.find("not defined at location"), std::string::npos);
  EXPECT_FALSE((EffectBlock{Effect::kSaturation, Location::kInput, {1.0, 0.0}}.IsValid(&err)));
  EXPECT_THROW(ParseEffect("stiction"), InputError);
  AugmentedModel m;
  m.nominal.linear = {{-1.5, 0.7}, {0.1, 0.1}, 1};
  m.block = {Effect::kStateSaturation, Location::kState, {-HUGE_VAL, 2.0}};
  const AugmentedModel back = AugmentedModel::from_json(nlohmann::json::parse(m.to_json().dump()));
  EXPECT_EQ(back.block.effect, Effect::kStateSaturation);
  EXPECT_TRUE(std::isinf(back.block.params[0]));
  EXPECT_EQ(back.block.params[1], 2.0);
  EXPECT_EQ(back.nominal.linear.delay, 1);
}

TEST(EffectBlocks, StateSaturationClampsInsideTheRecursion) {
  AugmentedModel m;
  m.nominal.linear = {{-0.9}, {0.1}, 0};  // first-order tank, DC gain 1
  m.block = {Effect::kStateSaturation, Location::kState, {-HUGE_VAL, 0.5}};
  const auto y = m.simulate(std::vector<double>(200, 1.0));
  EXPECT_NEAR(y.back(), 0.5, 1e-12);
  // Output saturation would hold the internal state at 1 and clip only the reading: same value here,
  // but the release after the input drops differs.
  std::vector<double> u(400, 1.0);
  for (std::size_t t = 200; t < 400; ++t) u[t] = 0.0;
  const auto ys = m.simulate(u);
  AugmentedModel o = m;
  o.block = {Effect::kSaturation, Location::kOutput, {-HUGE_VAL, 0.5}};
  const auto yo = o.simulate(u);
  EXPECT_LT(ys[205], yo[205]);
}

TEST(Refit, OutputErrorFitRecoversALinearSystem) {
  std::mt19937_64 rng(3);
  std::normal_distribution<double> g(0.0, 1.0);
  std::vector<double> u(800);
  for (auto& v : u) v = g(rng);
  HwModel truth;
  truth.linear = {{-1.2, 0.5}, {0.3, 0.2}, 0};
  const auto y = truth.simulate(u);
  const HwModel fit = FitNominal(NominalSpec::Parse("linear:2,2"), {&u, &y, 0});
  EXPECT_NEAR(fit.linear.a[0], -1.2, 1e-5);
  EXPECT_NEAR(fit.linear.a[1], 0.5, 1e-5);
  EXPECT_NEAR(fit.linear.b[0], 0.3, 1e-5);
  EXPECT_NEAR(fit.linear.b[1], 0.2, 1e-5);
  EXPECT_THROW(NominalSpec::Parse("linear:2"), InputError);
  EXPECT_THROW(NominalSpec::Parse("arx:2,2"), InputError);
  EXPECT_THROW(NominalSpec::Parse("linear:2,x"), InputError);
}

TEST(Refit, BacklashWidthIsRecoveredJointlyWithTheLinearBlock) {
  ScenarioOptions so;
  so.effect = Effect::kBacklash;
  so.effect_rms_ratio = 50.0;  // nearly noise-free: the estimate must land on the truth
  so.seed = 7;
  const Scenario sc = MakeScenario(so);
  const HwModel nominal = FitNominal(NominalSpec::Parse("linear:2,2"), {&sc.ident.u, &sc.ident.y, 0});
  const RefitResult r = RefitWithEffect(nominal, Effect::kBacklash, Location::kInput, {&sc.ident.u, &sc.ident.y, 0}, {});
  EXPECT_NEAR(r.model.block.params[0], sc.truth.block.params[0], 0.05 * sc.truth.block.params[0]);
  EXPECT_NEAR(r.model.nominal.linear.a[0], sc.truth.nominal.linear.a[0], 0.02);
}

TEST(Scenario, NoiseIsSetByTheEffectRmsRatio) {
  ScenarioOptions so;
  so.effect = Effect::kDeadzone;
  so.effect_rms_ratio = 2.0;
  so.effect_fraction = 0.05;
  const Scenario sc = MakeScenario(so);
  EXPECT_NEAR(sc.effect_rms / sc.noise_std, 2.0, 1e-9);
  double m = 0, s = 0;
  const auto w = sc.linear_truth.simulate(sc.ident.u);
  for (double v : w) m += v;
  m /= w.size();
  for (double v : w) s += (v - m) * (v - m);
  EXPECT_NEAR(sc.effect_rms / std::sqrt(s / w.size()), 0.05, 0.005);
  so.effect_rms_ratio = -1;
  EXPECT_THROW(MakeScenario(so), InputError);
}

TEST(ResidualAnalysis, WindowsRegionAndCorrelationTests) {
  std::mt19937_64 rng(5);
  std::normal_distribution<double> g(0.0, 1.0);
  const std::size_t n = 2000;
  std::vector<double> u(n), e(n), yhat(n);
  for (std::size_t t = 0; t < n; ++t) {
    u[t] = std::sin(0.01 * t);
    yhat[t] = u[t];
    e[t] = 0.1 * g(rng) + (u[t] > 0.8 ? 0.4 : 0.0);  // bias only where u is high
  }
  const double sigma = EstimateNoiseStd(e, 0);
  EXPECT_NEAR(sigma, 0.1, 0.015);
  const auto mask = MismatchMask(e, sigma, 0, {});
  const auto windows = MaskToWindows(mask);
  EXPECT_GE(windows.size(), 2u);
  const Region region = CharacteriseRegion(OperatingConditions(u, yhat), mask, e, 0);
  ASSERT_TRUE(region.found);
  EXPECT_TRUE(region.condition == "u" || region.condition == "y") << region.description;
  EXPECT_EQ(region.relation, "above");
  EXPECT_NEAR(region.threshold, 0.8, 0.1);
  std::vector<double> white(n), colored(n);
  for (std::size_t t = 0; t < n; ++t) {
    white[t] = g(rng);
    colored[t] = t ? 0.8 * colored[t - 1] + white[t] : white[t];
  }
  EXPECT_TRUE(WhitenessTest(white, 0, 25).passed);
  EXPECT_FALSE(WhitenessTest(colored, 0, 25).passed);
  EXPECT_FALSE(InputCorrelationTest(colored, white, 0, 25).passed);
  EXPECT_NEAR(ChiSquareQuantile(0.99, 25), 44.31, 0.3);
}

// The concealed-effect study in small: 3 scenarios per effect and location (effect RMS 1.5, 2.25 and
// 3 noise standard deviations) and 3 null scenarios, nominal = linear:2,2 fitted on the recording.
TEST(Study, ConfusionOnConcealedEffects) {
  StudyOptions o;
  o.seeds_per_effect = 3;
  o.null_scenarios = 3;
  o.samples = 1500;
  const StudyResult r = RunStudy(o);
  std::cout << r.to_markdown();
  EXPECT_EQ(r.false_alarm_rate, 0.0);
  EXPECT_GE(r.accuracy, 0.85);
  EXPECT_GE(r.location_accuracy, 0.95);
  // Every effect is named correctly in at least 2 of its 3 scenarios, except a small extra delay:
  // re-estimating the linear block (and output offset) absorbs most of it at these input bandwidths,
  // so "none" is often the statistically supported answer there (docs/diagnose.md); 1 of 3 required.
  for (std::size_t i = 0; i + 1 < r.rows.size(); ++i) {
    const std::string effect = r.rows[i].substr(0, r.rows[i].find('@'));
    const auto col = std::find(r.labels.begin(), r.labels.end(), effect) - r.labels.begin();
    EXPECT_GE(r.confusion[i][col], effect == "delay" ? 1 : 2) << r.rows[i];
    // A miss may only be "none": never a wrong effect name.
    EXPECT_EQ(r.confusion[i][col] + r.confusion[i].back(), 3) << r.rows[i];
  }
  EXPECT_EQ(r.confusion.back().back(), 3);  // null scenarios: verdict none
  EXPECT_GT(r.mean_fit_gain, 1.0);
  EXPECT_GT(r.mean_window_precision, 0.5);
}

TEST(Report, WritesJsonMarkdownAndSchemaKeys) {
  ScenarioOptions so;
  so.effect = Effect::kSaturation;
  so.seed = 2;
  so.samples = 1000;
  const Scenario sc = MakeScenario(so);
  const HwModel nominal = FitNominal(NominalSpec::Parse("linear:2,2"), {&sc.ident.u, &sc.ident.y, 0});
  DiagnoseReport r;
  Diagnose({}, nominal, sc.ident, sc.valid, &r);
  ASSERT_TRUE(r.ok) << r.message;
  const auto dir = (std::filesystem::temp_directory_path() / "hw_diagnose_test_report").string();
  std::filesystem::remove_all(dir);
  WriteReport(r, sc.ident, sc.valid, dir);
  std::ifstream in(dir + "/report.json");
  const auto j = nlohmann::json::parse(in);
  for (const char* k : {"verdict", "findings", "mismatch", "fit"}) EXPECT_TRUE(j.contains(k)) << k;
  EXPECT_TRUE(j["mismatch"].contains("windows"));
  EXPECT_TRUE(j["mismatch"].contains("region"));
  EXPECT_TRUE(j["fit"]["nominal"].contains("rmse"));
  EXPECT_TRUE(j["fit"]["augmented"].contains("fit_percent"));
  for (const auto& f : j["findings"])
    for (const char* k : {"effect", "location", "parameters", "evidence", "score"}) EXPECT_TRUE(f.contains(k)) << k;
  EXPECT_TRUE(std::filesystem::exists(dir + "/report.md"));
  std::filesystem::remove_all(dir);
}

TEST(Diagnose, RejectsTooShortRecordings) {
  Recording a;
  a.u = a.y = a.t = std::vector<double>(20, 0.0);
  HwModel m;
  m.linear = {{}, {1.0}, 0};
  DiagnoseReport r;
  Diagnose({}, m, a, a, &r);
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.message.find("too short"), std::string::npos);
}

}  // namespace
}  // namespace hw::diagnose
