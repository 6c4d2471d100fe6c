// Tests of the discrepancy diagnosis (diagnose/): effect blocks, strict model reading, recordings,
// refits with physical ranges, multi-start nominal fits, residual analysis and location. The
// concealed-effect study in small is in tests/diagnose_study_test.cpp.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>
#include <sys/wait.h>

#include <gtest/gtest.h>

#include "core/input_error.hpp"
#include "diagnose/diagnose.hpp"
#include "diagnose/effects.hpp"
#include "diagnose/locate.hpp"
#include "diagnose/nominal_fit.hpp"
#include "diagnose/recording.hpp"
#include "diagnose/refit.hpp"
#include "diagnose/residual_analysis.hpp"
#include "diagnose/scenario.hpp"

namespace hw::diagnose {
namespace {

using Vec = std::vector<double>;

TEST(EffectBlocks, BacklashIsAPlayOperator) {
  const Vec u = {0.0, 0.5, 1.0, 0.9, 0.6, 0.0};
  const auto x = ApplyInputBlock({Effect::kBacklash, Location::kInput, {0.2}}, u);
  const Vec want = {0.0, 0.3, 0.8, 0.8, 0.8, 0.2};
  for (std::size_t i = 0; i < u.size(); ++i) EXPECT_NEAR(x[i], want[i], 1e-12) << i;
}

TEST(EffectBlocks, RateLimitDelayRelayAndStaticMaps) {
  const Vec u = {0.0, 1.0, 1.0, 1.0, -1.0};
  const auto r = ApplyInputBlock({Effect::kRateLimit, Location::kInput, {0.4}}, u);
  EXPECT_NEAR(r[1], 0.4, 1e-12);
  EXPECT_NEAR(r[3], 1.0, 1e-12);
  EXPECT_NEAR(r[4], 0.6, 1e-12);
  const auto d = ApplyInputBlock({Effect::kDelay, Location::kInput, {2}}, u);
  EXPECT_EQ(d[3], u[1]);
  EXPECT_EQ(d[4], u[2]);
  const auto h = ApplyInputBlock({Effect::kHysteresis, Location::kInput, {0.5, 0.1}}, {0.0, 0.6, 0.0, -0.4, -0.6, 0.0});
  EXPECT_NEAR(h[2], 0.1, 1e-12);   // relay still on after u fell inside the band
  EXPECT_NEAR(h[3], -0.3, 1e-12);  // still on at -0.4
  EXPECT_NEAR(h[5], -0.1, 1e-12);  // switched off below -0.5
  EXPECT_NEAR(ApplyStaticBlock({Effect::kDeadzone, Location::kInput, {0.3}}, -0.5), -0.2, 1e-12);
  EXPECT_NEAR(ApplyStaticBlock({Effect::kSaturation, Location::kInput, {-HUGE_VAL, 0.7}}, 0.9), 0.7, 1e-12);
  EXPECT_NEAR(ApplyStaticBlock({Effect::kQuantization, Location::kOutput, {0.25}}, 0.3), 0.25, 1e-12);
}

TEST(EffectBlocks, StictionSticksThenSlips) {
  // Static band 0.3, kinetic lag 0.1: the stem holds until the input has moved 0.3 away, jumps to
  // within 0.1 of it, follows at lag 0.1, and sticks again when the input reverses.
  const Vec u = {0.0, 0.2, 0.35, 0.5, 0.6, 0.55, 0.3, 0.1};
  const auto x = ApplyInputBlock({Effect::kStiction, Location::kInput, {0.3, 0.1}}, u);
  const Vec want = {0.0, 0.0, 0.25, 0.4, 0.5, 0.5, 0.5, 0.2};
  for (std::size_t i = 0; i < u.size(); ++i) EXPECT_NEAR(x[i], want[i], 1e-12) << i;
  // With equal bands it is the play operator.
  const Vec s = {0.0, 0.5, 1.0, 0.9, 0.6, 0.0};
  const auto a = ApplyInputBlock({Effect::kStiction, Location::kInput, {0.2, 0.2}}, s);
  const auto b = ApplyInputBlock({Effect::kBacklash, Location::kInput, {0.2}}, s);
  for (std::size_t i = 0; i < s.size(); ++i) EXPECT_NEAR(a[i], b[i], 1e-12) << i;
}

TEST(EffectBlocks, StictionStopsOnEveryHoldWhateverTheRounding) {
  // A moving stem sits the kinetic band behind the input; when the input then holds still the stem must
  // stop, so a further small move in the same direction (smaller than the static band) leaves it stuck.
  // Without a tolerance, |u - (u - fd)| > fd held for about 4 in 10 of these (level, band) pairs.
  int moved_on = 0, cases = 0;
  for (int i = 1; i < 200; ++i)
    for (int j = 1; j < 20; ++j) {
      const double a = 0.8 + 0.073 * i, fd = 0.013 * j, fs = 3 * fd;  // a > fs: it breaks away
      const auto x = ApplyInputBlock({Effect::kStiction, Location::kInput, {fs, fd}}, {0.0, a, a, a + fd});
      ++cases;
      EXPECT_EQ(x[1], a - fd);  // broke away, kinetic band behind
      if (x[3] != x[2]) ++moved_on;
    }
  EXPECT_EQ(moved_on, 0) << "of " << cases;
}

TEST(EffectBlocks, CoulombFrictionHoldsAVelocityStateAtRest) {
  // Force -> velocity drive v_t = 0.9 v_{t-1} + 0.1 F_{t-1}; friction levels 0.05 (up) and 0.02 (down).
  AugmentedModel m;
  m.nominal.linear = {{-0.9}, {0.1}, 1};
  m.blocks = {{Effect::kCoulombFriction, Location::kState, {0.05, 0.02}, StateVariable::kVelocity}};
  const auto small = m.simulate(Vec(50, 0.3));  // drive 0.03 per step < 0.05: never moves
  for (double v : small) EXPECT_EQ(v, 0.0);
  const auto up = m.simulate(Vec(400, 1.0)), down = m.simulate(Vec(400, -1.0));
  EXPECT_NEAR(up.back(), (0.1 - 0.05) / 0.1, 1e-6);     // steady state (F - f+/b) with b = 0.1
  EXPECT_NEAR(down.back(), -(0.1 - 0.02) / 0.1, 1e-6);  // the downward level is lower
  for (std::size_t t = 1; t < up.size(); ++t) EXPECT_GE(up[t], 0.0);  // no chatter through zero
}

TEST(EffectBlocks, StateSaturationClampsInsideTheRecursion) {
  AugmentedModel m;
  m.nominal.linear = {{-0.9}, {0.1}, 0};  // first-order tank, DC gain 1
  m.blocks = {{Effect::kStateSaturation, Location::kState, {-HUGE_VAL, 0.5}}};
  EXPECT_NEAR(m.simulate(Vec(200, 1.0)).back(), 0.5, 1e-12);
  // Output saturation would hold the internal state at 1 and clip only the reading: the release
  // after the input drops differs.
  Vec u(400, 1.0);
  for (std::size_t t = 200; t < 400; ++t) u[t] = 0.0;
  const auto ys = m.simulate(u);
  AugmentedModel o = m;
  o.blocks = {{Effect::kSaturation, Location::kOutput, {-HUGE_VAL, 0.5}}};
  EXPECT_LT(ys[205], o.simulate(u)[205]);
}

TEST(EffectBlocks, InitialStateStartsTheRecursionAwayFromRest) {
  AugmentedModel m;
  m.nominal.linear = {{-0.8}, {0.2}, 0};
  m.initial_state = {2.0};
  const auto y = m.simulate(Vec(3, 0.0));
  EXPECT_NEAR(y[0], 1.6, 1e-12);
  EXPECT_NEAR(y[2], 1.6 * 0.8 * 0.8, 1e-12);
}

TEST(EffectBlocks, PhysicalRangesAreEnforced) {
  std::string err;
  EXPECT_FALSE((EffectBlock{Effect::kBacklash, Location::kState, {0.1}}.IsValid(&err)));
  EXPECT_NE(err.find("not defined at location"), std::string::npos);
  EXPECT_FALSE((EffectBlock{Effect::kSaturation, Location::kInput, {1.0, 0.0}}.IsValid(&err)));
  EXPECT_FALSE((EffectBlock{Effect::kCoulombFriction, Location::kState, {-0.1, 0.1}}.IsValid(&err)));
  EXPECT_FALSE((EffectBlock{Effect::kHysteresis, Location::kInput, {0.1, -0.2}}.IsValid(&err)));
  EXPECT_FALSE((EffectBlock{Effect::kStiction, Location::kInput, {0.1, 0.2}}.IsValid(&err)));
  EffectBlock f{Effect::kCoulombFriction, Location::kState, {-0.3, 0.2}};
  ClampToPhysicalRange(&f);
  EXPECT_EQ(f.params[0], 0.0);
  EXPECT_TRUE(f.IsValid(&err)) << err;
  EXPECT_THROW(ParseEffect("slipstick"), InputError);
}

TEST(ModelJson, AugmentedModelRoundTrip) {
  AugmentedModel m;
  m.nominal.linear = {{-1.5, 0.7}, {0.1, 0.1}, 1};
  m.blocks = {{Effect::kStateSaturation, Location::kState, {-HUGE_VAL, 2.0}},
              {Effect::kBacklash, Location::kInput, {0.05}}};
  m.output_offset = 0.3;
  m.initial_state = {0.5, -0.25};
  const AugmentedModel back = AugmentedModel::from_json(nlohmann::json::parse(m.to_json().dump()));
  ASSERT_EQ(back.blocks.size(), 2u);
  EXPECT_EQ(back.blocks[0].effect, Effect::kStateSaturation);
  EXPECT_TRUE(std::isinf(back.blocks[0].params[0]));
  EXPECT_EQ(back.blocks[0].params[1], 2.0);
  EXPECT_EQ(back.nominal.linear.delay, 1);
  EXPECT_EQ(back.output_offset, 0.3);
  EXPECT_EQ(back.initial_state, m.initial_state);
  const Vec u(50, 1.0);
  EXPECT_EQ(back.simulate(u), m.simulate(u));
}

TEST(ModelJson, UnknownOrMisspeltKeysAreRejectedWithTheirName) {
  const auto dir = std::filesystem::temp_directory_path() / "hw_diagnose_model_keys";
  std::filesystem::create_directories(dir);
  const std::string path = (dir / "other_layout.json").string();
  // Another tool's layout: polynomials and delay under keys this reader does not know.
  std::ofstream(path) << R"({"type": "hammerstein_wiener", "linear": {"a": [-0.5], "b": [1.0]},
                              "input_poly": [1.0, 0.0, 0.2], "nk": 2})";
  try {
    AugmentedModel::Load(path);
    FAIL() << "an unknown key was accepted";
  } catch (const InputError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find(path), std::string::npos) << m;
    EXPECT_NE(m.find("input_poly"), std::string::npos) << m;
  }
  const auto nested = nlohmann::json::parse(R"({"linear": {"a": [-0.5], "b": [1.0], "dealy": 1}})");
  EXPECT_THROW(AugmentedModel::from_json(nested), InputError);
  const auto block = nlohmann::json::parse(
      R"({"linear": {"b": [1.0]}, "effect_blocks": [{"effect": "backlash", "location": "input",
          "parameters": {"half_widht": 0.1}}]})");
  EXPECT_THROW(AugmentedModel::from_json(block), InputError);
  std::filesystem::remove_all(dir);
}

TEST(Recordings, OnlyUsedColumnsAreReadAndNamesMayDifferPerFile) {
  // Trailing comma in the header (an unnamed, mostly empty column), an unused column with text.
  const std::string text = "\"uEst\",\"uVal\",\"yEst\",\"yVal\",\"Ts\",\n"
                           "1,2,3,4,4,\n5,6,7,8,,\n9,10,11,12,,\n";
  ColumnNames est;
  est.u = "uEst", est.y = "yEst";
  const Recording r = ParseRecording(text, "bench.csv", est, 3);
  EXPECT_EQ(r.u, (Vec{1, 5, 9}));
  EXPECT_EQ(r.y, (Vec{3, 7, 11}));
  EXPECT_EQ(r.t, (Vec{0, 1, 2}));
  const RecordingSource spec = RecordingSource::Parse("bench.csv:u=uVal,y=yVal", ColumnNames{});
  EXPECT_EQ(spec.path, "bench.csv");
  EXPECT_EQ(ParseRecording(text, spec.path, spec.columns, 3).y, (Vec{4, 8, 12}));
  EXPECT_THROW(RecordingSource::Parse("bench.csv:w=uVal", ColumnNames{}), InputError);
  try {
    ParseRecording("u,y\n1,2\n3,x\n", "bad.csv", ColumnNames{}, 1);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("bad.csv:3"), std::string::npos) << e.what();
  }
  EXPECT_THROW(ParseRecording("a,y\n1,2\n", "x.csv", ColumnNames{}, 1), InputError);  // no column u
}

TEST(Refit, LinearFitRecoversALinearSystem) {
  std::mt19937_64 rng(3);
  std::normal_distribution<double> g(0.0, 1.0);
  Vec u(800);
  for (auto& v : u) v = g(rng);
  HwModel truth;
  truth.linear = {{-1.2, 0.5}, {0.3, 0.2}, 0};
  const auto y = truth.simulate(u);
  const NominalFit fit = FitNominal(NominalSpec::Parse("linear:2,2"), {&u, &y, 0, 0});
  EXPECT_NEAR(fit.model.nominal.linear.a[0], -1.2, 1e-4);
  EXPECT_NEAR(fit.model.nominal.linear.a[1], 0.5, 1e-4);
  EXPECT_NEAR(fit.model.nominal.linear.b[0], 0.3, 1e-4);
  EXPECT_NEAR(fit.model.nominal.linear.b[1], 0.2, 1e-4);
  EXPECT_GE(fit.starts.size(), 2u);
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
  const Segment seg{&sc.ident.u, &sc.ident.y, 0, 0};
  const AugmentedModel nominal = FitNominal(NominalSpec::Parse("linear:2,2"), seg).model;
  const RefitResult r = AddBlock(nominal, Effect::kBacklash, Location::kInput, StateVariable::kPosition, seg, {});
  ASSERT_EQ(r.model.blocks.size(), 1u);
  EXPECT_NEAR(r.model.blocks[0].params[0], sc.truth.blocks[0].params[0], 0.05 * sc.truth.blocks[0].params[0]);
  EXPECT_NEAR(r.model.nominal.linear.a[0], sc.truth.nominal.linear.a[0], 0.02);
}

// A relay threshold between two levels of a step input fits the data equally well anywhere between
// them; the grid (quantiles of |u|: the levels themselves) puts it on the lower level, and the fit must
// move it inside the interval (here (0.6, 1.0)), where a new level in between is predicted sensibly.
TEST(Refit, AThresholdBetweenTwoInputLevelsIsPlacedInsideTheInterval) {
  std::mt19937_64 rng(5);
  std::uniform_int_distribution<int> pick(0, 5), hold(8, 30);
  const Vec levels = {-1.0, -0.6, -0.2, 0.2, 0.6, 1.0};
  Vec u;
  while (u.size() < 900) u.insert(u.end(), hold(rng), levels[pick(rng)]);
  AugmentedModel truth;
  truth.nominal.linear = {{-0.8}, {0.2}, 0};
  truth.blocks.push_back({Effect::kHysteresis, Location::kInput, {0.8, 0.3}, StateVariable::kPosition});
  Vec y = truth.simulate(u);
  std::normal_distribution<double> g(0.0, 0.01);
  for (auto& v : y) v += g(rng);
  const Segment seg{&u, &y, 0, 0};
  AugmentedModel nominal = truth.WithoutBlocks();
  const RefitResult r = AddBlock(nominal, Effect::kHysteresis, Location::kInput, StateVariable::kPosition, seg, {});
  ASSERT_EQ(r.model.blocks.size(), 1u);
  EXPECT_GT(r.model.blocks[0].params[0], 0.65);
  EXPECT_LT(r.model.blocks[0].params[0], 0.95);
  EXPECT_NEAR(r.model.blocks[0].params[1], 0.3, 0.03);
}

// n samples of first-order filtered white noise, v_t = pole v_{t-1} + gain e_t, drawn from rng.
Vec FilteredNoise(std::mt19937_64& rng, std::size_t n, double pole, double gain) {
  std::normal_distribution<double> g(0.0, 1.0);
  Vec u(n);
  double lp = 0.0;
  for (auto& v : u) v = lp = pole * lp + gain * g(rng);
  return u;
}

// Random steps over a few levels (holds of 8-30 samples).
Vec FewLevelSteps(std::mt19937_64& rng, const Vec& levels, std::size_t n) {
  std::uniform_int_distribution<int> pick(0, static_cast<int>(levels.size()) - 1), hold(8, 30);
  Vec u;
  while (u.size() < n) u.insert(u.end(), hold(rng), levels[pick(rng)]);
  u.resize(n);
  return u;
}

// Random steps of uniformly drawn levels in [lo, hi], each held for a uniform hold_min-hold_max samples.
Vec UniformSteps(std::mt19937_64& rng, std::size_t n, double lo, double hi, int hold_min, int hold_max) {
  std::uniform_real_distribution<double> level(lo, hi);
  std::uniform_int_distribution<int> hold(hold_min, hold_max);
  Vec u;
  while (u.size() < n) u.insert(u.end(), hold(rng), level(rng));
  u.resize(n);
  return u;
}

// A stiction block added to the truth's nominal (refitted without it) on the truth's output for input u
// with white noise of standard deviation `noise` drawn from rng.
RefitResult StictionAddedToNoisyRecording(const AugmentedModel& truth, const Vec& u, double noise,
                                          std::mt19937_64& rng) {
  Vec y = truth.simulate(u);
  std::normal_distribution<double> g(0.0, noise);
  for (auto& v : y) v += g(rng);
  const Segment seg{&u, &y, 0, 0};
  const AugmentedModel nominal = RefitModel(truth.WithoutBlocks(), seg, {}).model;
  return AddBlock(nominal, Effect::kStiction, Location::kInput, StateVariable::kPosition, seg, {});
}

// A saturation whose limit lies between the two top levels of a step input: every quantile of the
// input is a level, and a limit at a level clips nothing of it. With a nominal fitted without the block
// (its cubic output map absorbed part of the clipping, and no numerator can be re-solved under it), the
// grid points at the levels are no better than the baseline; the limit between the levels is a start.
TEST(Refit, ASaturationBetweenTwoInputLevelsIsFoundFromTheGapBetweenThem) {
  std::mt19937_64 rng(21);
  const Vec u = FewLevelSteps(rng, {-1.0, -0.6, -0.2, 0.2, 0.6, 1.0}, 1000);
  AugmentedModel truth;
  truth.nominal.linear = {{-0.8}, {0.2}, 0};
  truth.nominal.output = StaticMap::Polynomial({1.0, 0.1, 0.2});
  truth.blocks.push_back({Effect::kSaturation, Location::kInput, {-HUGE_VAL, 0.8}, StateVariable::kPosition});
  Vec y = truth.simulate(u);
  std::normal_distribution<double> g(0.0, 0.01);
  for (auto& v : y) v += g(rng);
  const Segment seg{&u, &y, 0, 0};
  const AugmentedModel nominal = RefitModel(truth.WithoutBlocks(), seg, {}).model;
  const RefitResult r = AddBlock(nominal, Effect::kSaturation, Location::kInput, StateVariable::kPosition, seg, {});
  ASSERT_EQ(r.model.blocks.size(), 1u);
  EXPECT_GT(r.model.blocks[0].params[1], 0.65);
  EXPECT_LT(r.model.blocks[0].params[1], 0.95);
  EXPECT_LT(r.sse, 2.0 * u.size() * 0.01 * 0.01);
}

// The input map must be monotone where it acts: after an input limit, not out to the unclipped input's
// extremes. A map folding back below the limit is never seen, and judged over the whole input it would
// refuse every step of a fit that puts the limit where the map had bent to mimic it.
TEST(Refit, AnInputMapIsJudgedMonotoneOnTheInputAfterTheInputBlocks) {
  Vec u;
  for (int t = 0; t < 200; ++t) u.push_back(2.0 * std::sin(0.07 * t));
  AugmentedModel m;
  m.nominal.linear = {{-0.5}, {0.5}, 0};
  m.nominal.input = StaticMap::Polynomial({1.0, 0.4});  // slope 1 + 0.8 v: folds back below v = -1.25
  EXPECT_FALSE(MapsMonotone(m, u));
  m.blocks.push_back({Effect::kSaturation, Location::kInput, {-1.0, HUGE_VAL}, StateVariable::kPosition});
  EXPECT_TRUE(MapsMonotone(m, u));
}

// The consequence in a fit: the nominal refitted without the limit bends its cubic input map to zero slope
// at the lowest input (as far as monotone allows) to mimic the clipping. With the limit added, the map
// must straighten where the limit now clips; judged over the unclipped input, every step that does so
// was refused and the limit stayed where the grid put it (1.3 instead of 1.0, 2.8x the noise's cost).
TEST(Refit, AnInputLimitIsFoundUnderAnInputMapBentToMimicIt) {
  std::mt19937_64 rng(1);
  std::normal_distribution<double> g(0.0, 1.0);
  const Vec u = FilteredNoise(rng, 700, 0.85, 0.5);
  AugmentedModel truth;
  truth.nominal.linear = {{-0.6}, {0.25, 0.12}, 0};
  truth.nominal.input = StaticMap::Polynomial({1.0, 0.15, 0.03});
  truth.blocks.push_back({Effect::kSaturation, Location::kInput, {-1.0, HUGE_VAL}, StateVariable::kPosition});
  Vec y = truth.simulate(u);
  for (auto& v : y) v += 0.015 * g(rng);
  const Segment seg{&u, &y, 0, 0};
  const AugmentedModel nominal = RefitModel(truth.WithoutBlocks(), seg, {}).model;
  const RefitResult r = AddBlock(nominal, Effect::kSaturation, Location::kInput, StateVariable::kPosition, seg, {},
                                 LimitSides::kLower);
  ASSERT_EQ(r.model.blocks.size(), 1u);
  EXPECT_NEAR(r.model.blocks[0].params[0], -1.0, 0.03);
  EXPECT_LT(r.sse, 1.3 * u.size() * 0.015 * 0.015);
}

// On a two-level input (PRBS) every quantile of the input is one of its two levels: a limit there clips
// nothing, and no finite limit was tried at all (the fit returned no block). A limit that moves the low
// level inwards starts between the two levels and is refined to the truth. The nominal's maps are held
// (with them refitted, an affine change of a two-level input is absorbed by the gain, the output map and
// the offset).
TEST(Refit, ASaturationOfATwoLevelInputIsFound) {
  std::mt19937_64 rng(31);
  const Vec u = FewLevelSteps(rng, {-1.0, 0.7}, 900);
  AugmentedModel truth;
  truth.nominal.linear = {{-0.7}, {0.3}, 0};
  truth.nominal.output = StaticMap::Polynomial({1.0, 0.1, 0.2});
  truth.blocks.push_back({Effect::kSaturation, Location::kInput, {-0.8, HUGE_VAL}, StateVariable::kPosition});
  Vec y = truth.simulate(u);
  std::normal_distribution<double> g(0.0, 0.01);
  for (auto& v : y) v += g(rng);
  const Segment seg{&u, &y, 0, 0};
  RefitOptions o;
  o.refit_maps = false;
  const AugmentedModel nominal = RefitModel(truth.WithoutBlocks(), seg, o).model;
  const RefitResult r = AddBlock(nominal, Effect::kSaturation, Location::kInput, StateVariable::kPosition, seg, o,
                                 LimitSides::kLower);
  ASSERT_EQ(r.model.blocks.size(), 1u);
  EXPECT_NEAR(r.model.blocks[0].params[0], -0.8, 0.03);
  EXPECT_LT(r.sse, 2.0 * u.size() * 0.01 * 0.01);
}

// Stiction whose kinetic band is well below its static band, on steps: the backlash start settles on a
// play between the two, and only a joint move of both bands (static up, kinetic down) opens the jump.
TEST(Refit, StictionBandsAreSearchedTogetherFromTheBacklashStart) {
  std::mt19937_64 rng(8);
  const Vec u = UniformSteps(rng, 1000, -1.0, 1.0, 8, 30);
  AugmentedModel truth;
  truth.nominal.linear = {{-0.8}, {0.2}, 0};
  truth.blocks.push_back({Effect::kStiction, Location::kInput, {0.4, 0.1}, StateVariable::kPosition});
  const RefitResult r = StictionAddedToNoisyRecording(truth, u, 0.005, rng);
  ASSERT_EQ(r.model.blocks.size(), 1u);
  EXPECT_NEAR(r.model.blocks[0].params[0], 0.4, 0.08);
  EXPECT_NEAR(r.model.blocks[0].params[1], 0.1, 0.04);
  EXPECT_LT(r.sse, 2.0 * u.size() * 0.005 * 0.005);
}

// The same under a cubic output map, where the numerator, offset and initial state are not linear in the
// output: every band pair tried is scored with them re-solved through the map. Held at the values that
// fitted the backlash start, the true pair costs more than a poorer one, and the fit stays with the
// kinetic band near the play and no jump worth naming.
TEST(Refit, StictionBandsAreSearchedThroughAPolynomialOutputMap) {
  std::mt19937_64 rng(4);
  const Vec u = UniformSteps(rng, 600, -1.5, 1.5, 20, 60);
  AugmentedModel truth;
  truth.nominal.linear = {{-0.9, 0.8}, {1.0, -0.13}, 0};
  truth.nominal.output = StaticMap::Polynomial({1.0, 0.17, 0.11});
  truth.blocks.push_back({Effect::kStiction, Location::kInput, {0.45, 0.18}, StateVariable::kPosition});
  const RefitResult r = StictionAddedToNoisyRecording(truth, u, 0.03, rng);
  ASSERT_EQ(r.model.blocks.size(), 1u);
  EXPECT_NEAR(r.model.blocks[0].params[1], 0.18, 0.02);
  EXPECT_GT(r.model.blocks[0].params[0], 0.3);
  EXPECT_LT(r.sse, 1.2 * u.size() * 0.03 * 0.03);  // the backlash-side optimum costs 1.8x the noise
}

// Under an output quantizer the output offset moves the prediction by whole steps: started a third of a
// step away from the truth (as a nominal fitted without the quantizer leaves it), LM alone cannot
// descend the staircase; the offset search puts it back within a tenth of a step.
TEST(Refit, TheOffsetUnderAnOutputQuantizerIsSearchedNotLeftWhereTheNominalPutIt) {
  std::mt19937_64 rng(3);
  const Vec u = FilteredNoise(rng, 800, 0.9, 0.3);
  std::normal_distribution<double> g(0.0, 1.0);
  AugmentedModel truth;
  truth.nominal.linear = {{-0.7}, {0.5}, 0};
  truth.blocks.push_back({Effect::kQuantization, Location::kOutput, {0.25, 0.0}, StateVariable::kPosition});
  Vec y = truth.simulate(u);
  for (auto& v : y) v += 0.02 * g(rng);
  const Segment seg{&u, &y, 0, 0};
  AugmentedModel start = truth;
  start.output_offset = 0.25 / 3;
  RefitOptions o;
  o.estimate_initial_state = false;
  const RefitResult r = RefitModel(start, seg, o);
  ASSERT_EQ(r.model.blocks.size(), 1u);
  EXPECT_NEAR(r.model.output_offset, 0.0, 0.025);
  EXPECT_LT(r.sse, SumSquaredError(start, seg));
}

// The set-up the re-solves of the numerator (with a map or a block around it) share: a first-order system
// (b = 0.4, 0.2) driven by filtered noise with noise 0.01, and a start whose numerator, offset and initial
// state are far off.
AugmentedModel FirstOrderTruth(int delay = 0) {
  AugmentedModel truth;
  truth.nominal.linear = {{-0.6}, {0.4, 0.2}, delay};
  return truth;
}

struct ReSolveCase {
  Vec u, y;
  AugmentedModel start;
};

ReSolveCase ReSolveCaseFor(const AugmentedModel& truth, unsigned seed, double input_gain = 0.4) {
  std::mt19937_64 rng(seed);
  ReSolveCase c;
  c.u = FilteredNoise(rng, 600, 0.8, input_gain);
  std::normal_distribution<double> g(0.0, 1.0);
  c.y = truth.simulate(c.u);
  for (auto& v : c.y) v += 0.01 * g(rng);
  c.start = truth;
  c.start.nominal.linear.b = {0.25, 0.05};
  c.start.output_offset = 0.0;
  c.start.initial_state = {0.0};
  return c;
}

// The re-solved start has the truth's numerator (0.4, 0.2) and output offset within `tolerance` and fits
// the recording to its noise.
void ExpectNumeratorAndOffsetRecovered(const ReSolveCase& c, double offset, double tolerance) {
  const Segment seg{&c.u, &c.y, 0, 0};
  EXPECT_NEAR(c.start.nominal.linear.b[0], 0.4, tolerance);
  EXPECT_NEAR(c.start.nominal.linear.b[1], 0.2, tolerance);
  EXPECT_NEAR(c.start.output_offset, offset, tolerance);
  EXPECT_LT(SumSquaredError(c.start, seg), 1.5 * 600 * 0.01 * 0.01);
}

// Under a polynomial output map the output is not linear in the numerator, offset and initial state; the
// Gauss-Newton re-solve through the map (poles held) recovers them from a start far off.
TEST(Refit, NumeratorOffsetAndInitialStateAreReSolvedThroughAPolynomialOutputMap) {
  AugmentedModel truth = FirstOrderTruth();
  truth.nominal.output = StaticMap::Polynomial({1.0, 0.0, 0.3});
  truth.output_offset = 0.3;
  truth.initial_state = {1.5};
  ReSolveCase c = ReSolveCaseFor(truth, 5);
  const Segment seg{&c.u, &c.y, 0, 0};
  AugmentedModel& start = c.start;
  EXPECT_TRUE(SolveNumeratorThroughOutputMap(&start, seg, {}));
  ExpectNumeratorAndOffsetRecovered(c, 0.3, 0.01);
  AugmentedModel identity = start;  // no polynomial output map: not this re-solve's case
  identity.nominal.output = StaticMap{};
  EXPECT_FALSE(SolveNumeratorThroughOutputMap(&identity, seg, {}));
}

// Under a polynomial input map the output is bilinear in the numerator and the map; the over-parametrised
// least squares (poles held) with its rank-one split recovers both, the offset and the initial state, with
// the input after an input quantizer, from a start whose map is the identity.
TEST(Refit, InputMapNumeratorOffsetAndInitialStateAreReSolvedAfterTheInputBlocks) {
  AugmentedModel truth = FirstOrderTruth(1);
  truth.nominal.input = StaticMap::Polynomial({1.0, 0.2, 0.3});
  truth.blocks = {{Effect::kQuantization, Location::kInput, {0.15, 0.05}}};
  truth.output_offset = 0.3;
  truth.initial_state = {1.5};
  ReSolveCase c = ReSolveCaseFor(truth, 7, 0.6);
  const Segment seg{&c.u, &c.y, 0, 0};
  AugmentedModel& start = c.start;
  start.nominal.input = StaticMap::Polynomial({1.0, 0.0, 0.0});
  ASSERT_TRUE(SolveInputMapAndNumerator(&start, seg, {}));
  EXPECT_NEAR(start.nominal.input.coefficients[1], 0.2, 0.02);
  EXPECT_NEAR(start.nominal.input.coefficients[2], 0.3, 0.02);
  ExpectNumeratorAndOffsetRecovered(c, 0.3, 0.01);
  AugmentedModel identity = truth;  // no polynomial input map: not this re-solve's case
  identity.nominal.input = StaticMap{};
  EXPECT_FALSE(SolveInputMapAndNumerator(&identity, seg, {}));
}

// An output dead band is not linear in the numerator, offset and initial state either: the re-solve
// linearises through the band (slope 0 inside, 1 outside) and recovers them; an output quantizer is not
// this re-solve's case.
TEST(Refit, NumeratorOffsetAndInitialStateAreReSolvedThroughAnOutputDeadBand) {
  AugmentedModel truth = FirstOrderTruth();
  truth.blocks = {{Effect::kDeadzone, Location::kOutput, {0.3, 0.1}}};
  truth.output_offset = 0.2;
  truth.initial_state = {1.0};
  ReSolveCase c = ReSolveCaseFor(truth, 6);
  const Segment seg{&c.u, &c.y, 0, 0};
  AugmentedModel& start = c.start;
  EXPECT_TRUE(SolveNumeratorThroughOutputMap(&start, seg, {}, 6));
  ExpectNumeratorAndOffsetRecovered(c, 0.2, 0.02);
  AugmentedModel quantized = start;
  quantized.blocks = {{Effect::kQuantization, Location::kOutput, {0.1, 0.0}}};
  EXPECT_FALSE(SolveNumeratorThroughOutputMap(&quantized, seg, {}));
}

// Data from a mass–spring–damper whose "friction" pushes along the motion (a negative Coulomb level):
// an unconstrained fit returns a negative coefficient; the diagnosis must never report one.
TEST(Refit, FrictionIsNeverReportedWithANegativeLevel) {
  std::mt19937_64 rng(11);
  std::normal_distribution<double> g(0.0, 1.0);
  ScenarioOptions so;
  so.seed = 5;
  const Scenario base = MakeScenario(so);  // a null scenario: its input and linear part
  auto simulate_pushing = [&](const Vec& u) {
    const auto& lin = base.linear_truth.linear;
    Vec z(u.size(), 0.0);
    for (std::size_t t = 2; t < u.size(); ++t) {
      const double v = z[t - 1] - z[t - 2];
      z[t] = -lin.a[0] * z[t - 1] - lin.a[1] * z[t - 2] + lin.b[0] * u[t] + lin.b[1] * u[t - 1] +
             0.004 * (v > 0 ? 1.0 : (v < 0 ? -1.0 : 0.0));
    }
    for (auto& v : z) v += 0.002 * g(rng);
    return z;
  };
  Recording ident = base.ident, valid = base.valid;
  ident.y = simulate_pushing(ident.u);
  valid.y = simulate_pushing(valid.u);
  DiagnoseOptions o;
  o.threads = 1;
  DiagnoseReport r;
  Diagnose(o, AugmentedModel{base.linear_truth, {}, 0.0, {}}, nullptr, ident, valid, &r);
  ASSERT_TRUE(r.ok) << r.message;
  bool seen = false;
  for (const auto& f : r.findings)
    for (const auto& b : f.model.blocks)
      if (b.effect == Effect::kCoulombFriction) {
        seen = true;
        EXPECT_GE(b.params[0], 0.0);
        EXPECT_GE(b.params[1], 0.0);
      }
  EXPECT_TRUE(seen);
  EXPECT_NE(r.verdict, Effect::kCoulombFriction) << r.message;
}

// What an effect block changes in the prediction decays to round-off away from where it acts: the
// ratio of mean squares there and elsewhere is capped instead of reading 1e40 (a figure of round-off).
TEST(ResidualAnalysis, ChangeThatIsRoundOffElsewhereGivesACappedRatio) {
  const std::size_t n = 1000;
  Vec u(n), change(n);
  std::vector<bool> mask(n);
  for (std::size_t t = 0; t < n; ++t) {
    u[t] = std::sin(0.01 * t);
    mask[t] = u[t] > 0.8;
    change[t] = mask[t] ? 0.3 : 1e-25 * std::cos(0.3 * t);
  }
  const Region region = CharacteriseRegion(OperatingConditions(u, u), mask, change, 0, "change");
  ASSERT_TRUE(region.found);
  EXPECT_LE(region.lift, 1e6);
  EXPECT_EQ(region.description.find("e+"), std::string::npos) << region.description;
}

TEST(ResidualAnalysis, WindowsRegionAndCorrelationTests) {
  std::mt19937_64 rng(5);
  std::normal_distribution<double> g(0.0, 1.0);
  const std::size_t n = 2000;
  Vec u(n), e(n), yhat(n);
  for (std::size_t t = 0; t < n; ++t) {
    u[t] = std::sin(0.01 * t);
    yhat[t] = u[t];
    e[t] = 0.1 * g(rng) + (u[t] > 0.8 ? 0.4 : 0.0);  // bias only where u is high
  }
  const double sigma = EstimateNoiseStd(e, 0);
  EXPECT_NEAR(sigma, 0.1, 0.015);
  const auto mask = MismatchMask(e, sigma, 0, {});
  EXPECT_GE(MaskToWindows(mask).size(), 2u);
  const Region region = CharacteriseRegion(OperatingConditions(u, yhat), mask, e, 0);
  ASSERT_TRUE(region.found);
  EXPECT_TRUE(region.condition == "u" || region.condition == "y") << region.description;
  EXPECT_EQ(region.relation, "above");
  EXPECT_NEAR(region.threshold, 0.8, 0.1);
  // Pure noise: the family-wise threshold flags (almost) nothing.
  Vec white(n), colored(n);
  for (std::size_t t = 0; t < n; ++t) {
    white[t] = g(rng);
    colored[t] = t ? 0.8 * colored[t - 1] + white[t] : white[t];
  }
  const auto none = MismatchMask(white, 1.0, 0, {});
  EXPECT_LT(std::count(none.begin(), none.end(), true), static_cast<long>(n / 50));
  EXPECT_TRUE(WhitenessTest(white, 0, 25).passed);
  EXPECT_FALSE(WhitenessTest(colored, 0, 25).passed);
  EXPECT_FALSE(InputCorrelationTest(colored, white, 0, 25).passed);
  EXPECT_NEAR(ChiSquareQuantile(0.99, 25), 44.31, 0.3);
}

TEST(Locate, BlockEffectMaskAndIntersectionOverUnion) {
  AugmentedModel m;
  m.nominal.linear = {{-0.5}, {0.5}, 0};
  m.blocks = {{Effect::kSaturation, Location::kOutput, {-HUGE_VAL, 0.8}}};
  Vec u(100, 0.0);
  for (std::size_t t = 40; t < 60; ++t) u[t] = 1.0;
  Vec d;
  const auto mask = BlockEffectMask(m, u, 0.05, 0, &d);
  for (std::size_t t = 0; t < 40; ++t) EXPECT_FALSE(mask[t]);
  EXPECT_TRUE(mask[55]);
  EXPECT_NEAR(d[55], 0.8 - (1.0 - std::pow(0.5, 16)), 1e-9);
  std::vector<bool> a(10, false), b(10, false);
  a[1] = a[2] = b[2] = b[3] = true;
  EXPECT_NEAR(IntersectionOverUnion(a, b, 0), 1.0 / 3, 1e-12);
  EXPECT_EQ(IntersectionOverUnion(std::vector<bool>(5, false), std::vector<bool>(5, false), 0), 1.0);
}

TEST(Diagnose, RejectsTooShortRecordingsAndNominalsWithBlocks) {
  Recording a;
  a.u = a.y = a.t = Vec(20, 0.0);
  AugmentedModel m;
  m.nominal.linear = {{}, {1.0}, 0};
  DiagnoseReport r;
  Diagnose({}, m, nullptr, a, a, &r);
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.message.find("too short"), std::string::npos);
  m.blocks = {{Effect::kBacklash, Location::kInput, {0.1}}};
  a.u = a.y = a.t = Vec(200, 0.0);
  Diagnose({}, m, nullptr, a, a, &r);
  EXPECT_FALSE(r.ok);
}

TEST(Report, WritesJsonMarkdownAndSchemaKeys) {
  ScenarioOptions so;
  so.effect = Effect::kSaturation;
  so.seed = 2;
  so.samples = 1000;
  const Scenario sc = MakeScenario(so);
  const NominalSpec spec = NominalSpec::Parse("linear:2,2");
  const AugmentedModel nominal = FitNominal(spec, {&sc.ident.u, &sc.ident.y, 0, 0}).model;
  DiagnoseReport r;
  Diagnose({}, nominal, &spec, sc.ident, sc.valid, &r);
  ASSERT_TRUE(r.ok) << r.message;
  const auto dir = (std::filesystem::temp_directory_path() / "hw_diagnose_test_report").string();
  std::filesystem::remove_all(dir);
  WriteReport(r, sc.ident, sc.valid, dir);
  std::ifstream in(dir + "/report.json");
  const auto j = nlohmann::json::parse(in);
  for (const char* k : {"verdict", "verdict_blocks", "baseline", "findings", "pairs", "mismatch", "fit"})
    EXPECT_TRUE(j.contains(k)) << k;
  EXPECT_TRUE(j["mismatch"].contains("windows"));
  EXPECT_TRUE(j["mismatch"].contains("flagged_fraction"));
  EXPECT_TRUE(j["fit"]["nominal"].contains("rmse"));
  EXPECT_FALSE(j["baseline"]["starts"].empty());
  for (const auto& f : j["findings"])
    for (const char* k : {"effect", "location", "parameters", "blocks", "evidence", "score", "eligible"})
      EXPECT_TRUE(f.contains(k)) << k;
  EXPECT_TRUE(std::filesystem::exists(dir + "/report.md"));
  // A person reads the verdict once: the block is named once, with its parameters, and no share exceeds 100 %.
  std::ifstream md_in(dir + "/report.md");
  const std::string md((std::istreambuf_iterator<char>(md_in)), std::istreambuf_iterator<char>());
  const std::string verdict_line = md.substr(md.find("**Verdict:**"), md.find('\n', md.find("**Verdict:**")) - md.find("**Verdict:**"));
  ASSERT_NE(r.verdict, Effect::kNone) << r.message;  // the hidden saturation is found
  {
    const std::string label = r.augmented_model.Label();
    std::size_t count = 0;
    for (std::size_t pos = verdict_line.find(label); pos != std::string::npos; pos = verdict_line.find(label, pos + 1)) ++count;
    EXPECT_EQ(count, 1u) << verdict_line;
  }
  EXPECT_EQ(verdict_line.find("verdict:"), std::string::npos) << verdict_line;
  // The augmented model written beside the report reads back.
  EXPECT_NO_THROW(AugmentedModel::Load(dir + "/augmented_model.json"));
  std::filesystem::remove_all(dir);
}

#ifdef HW_CLI_PATH
// The command line: different column names per recording, and a model file in another layout is an
// error (exit code 2) naming the unknown key, with nothing written.
TEST(Cli, ColumnNamesPerFileAndStrictModelFiles) {
  const auto dir = std::filesystem::temp_directory_path() / "hw_diagnose_cli";
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  ScenarioOptions so;
  so.seed = 3;
  so.samples = 600;
  const Scenario sc = MakeScenario(so);
  {
    std::ofstream f(dir / "bench.csv");
    f << "\"uEst\",\"yEst\",\"uVal\",\"yVal\",\n";
    for (std::size_t t = 0; t < sc.ident.u.size(); ++t)
      f << sc.ident.u[t] << "," << sc.ident.y[t] << "," << sc.valid.u[t] << "," << sc.valid.y[t] << ",\n";
  }
  std::ofstream(dir / "bad.json") << R"({"linear": {"a": [-1.2, 0.5], "b": [0.2, 0.1]}, "output_poly": [1, 0.5]})";
  const std::string bench = (dir / "bench.csv").string();
  const std::string base = std::string(HW_CLI_PATH) + " diagnose --data " + bench + ":u=uEst,y=yEst --validate " +
                           bench + ":u=uVal,y=yVal --threads 1 ";
  const std::string log = (dir / "log.txt").string();
  EXPECT_EQ(std::system((base + "--fit linear:2,2 --out " + (dir / "ok").string() + " > " + log + " 2>&1").c_str()), 0);
  EXPECT_TRUE(std::filesystem::exists(dir / "ok" / "report.json"));
  const int rc = std::system((base + "--model " + (dir / "bad.json").string() + " --out " + (dir / "bad").string() +
                              " > " + log + " 2>&1").c_str());
  EXPECT_EQ(WEXITSTATUS(rc), 2);
  std::ifstream in(log);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("output_poly"), std::string::npos) << text;
  EXPECT_FALSE(std::filesystem::exists(dir / "bad"));
  std::filesystem::remove_all(dir);
}
#endif

}  // namespace
}  // namespace hw::diagnose
