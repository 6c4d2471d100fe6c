// The second scenario generator (open study), operating-point offsets, feedback detection and the
// nominal's noise-floor status. Development seeds only (1..99999 and retired reporting ranges); the
// reported study uses a range never run before.
#include <algorithm>
#include <cmath>
#include <iostream>
#include <set>

#include <gtest/gtest.h>

#include "diagnose/diagnose.hpp"
#include "diagnose/open_scenario.hpp"
#include "diagnose/open_study.hpp"
#include "diagnose/refit.hpp"
#include "diagnose/scenario.hpp"

namespace hw::diagnose {
namespace {

TEST(OpenScenario, VariesStructureInputAndOffsetsAndIsReproducible) {
  std::set<std::string> inputs, structures;
  int offsets = 0;
  for (unsigned seed = 1; seed <= 20; ++seed) {
    OpenScenarioOptions o;
    o.effect = Effect::kBacklash;
    o.seed = seed;
    const OpenScenario a = MakeOpenScenario(o), b = MakeOpenScenario(o);
    ASSERT_EQ(a.ident.y, b.ident.y) << "seed " << seed;
    inputs.insert(InputKindName(a.input));
    structures.insert(a.structure.Text());
    offsets += a.u_offset != 0.0;
    EXPECT_GE(a.ident.y.size(), 600u);
    EXPECT_LE(a.ident.y.size(), 1400u);
    EXPECT_GT(a.ratio, 0.3) << "seed " << seed;
    EXPECT_LT(a.ratio, 4.0) << "seed " << seed;
  }
  EXPECT_GE(inputs.size(), 4u);
  EXPECT_GE(structures.size(), 6u);
  EXPECT_GT(offsets, 2);
  EXPECT_LT(offsets, 18);
}

// The closed-loop input depends on past noise: the Granger test finds it; an open-loop input does not.
TEST(Feedback, ClosedLoopIsDetectedOpenLoopIsNot) {
  int closed_seen = 0, open_seen = 0;
  for (unsigned seed = 1; seed <= 40 && (closed_seen < 2 || open_seen < 2); ++seed) {
    OpenScenarioOptions o;
    o.seed = seed;
    const OpenScenario sc = MakeOpenScenario(o);
    const bool closed = sc.input == InputKind::kClosedLoop;
    if ((closed && closed_seen >= 2) || (!closed && open_seen >= 2)) continue;
    const Recording r = OperatingPoint::Of(sc.ident).Centred(sc.ident);
    AugmentedModel truth = sc.truth;
    std::vector<double> e = r.y, yhat = truth.simulate(r.u);
    for (std::size_t t = 0; t < e.size(); ++t) e[t] -= yhat[t];
    if (sc.y_offset != 0.0) continue;  // keep the residual exact: only scenarios recorded around 0
    const FeedbackTest f = DetectFeedback(r.u, e, 0, 10);
    std::cout << "feedback seed " << seed << " closed " << closed << " statistic " << f.statistic << "\n";
    EXPECT_EQ(f.detected, closed) << "seed " << seed << " statistic " << f.statistic << " threshold " << f.threshold;
    (closed ? closed_seen : open_seen)++;
  }
  EXPECT_EQ(closed_seen, 2);
  EXPECT_EQ(open_seen, 2);
}

// A recording around a large operating point gets the same verdict as the same recording centred.
TEST(OperatingPoint, LargeOffsetGivesTheSameVerdictAsTheCentredRecording) {
  ScenarioOptions so;
  so.effect = Effect::kDeadzone;
  so.seed = 2;
  so.samples = 1000;
  so.effect_rms_ratio = 3.0;
  const Scenario sc = MakeScenario(so);
  Recording ident = sc.ident, valid = sc.valid;
  for (auto* r : {&ident, &valid}) {
    for (auto& v : r->u) v += 50.0;
    for (auto& v : r->y) v += 120.0;
  }
  const NominalSpec spec = NominalSpec::Parse("linear:2,2");
  DiagnoseOptions o;
  o.threads = 1;
  DiagnoseReport centred, offset;
  Diagnose(o, FitNominalForDiagnosis(spec, sc.ident, o).model, &spec, sc.ident, sc.valid, &centred);
  Diagnose(o, FitNominalForDiagnosis(spec, ident, o).model, &spec, ident, valid, &offset);
  ASSERT_TRUE(centred.ok && offset.ok);
  EXPECT_EQ(centred.augmented_model.Label(), "deadzone@input") << centred.message;
  EXPECT_EQ(offset.augmented_model.Label(), centred.augmented_model.Label()) << offset.message;
  EXPECT_TRUE(offset.operating_point.u_removed && offset.operating_point.y_removed);
  // The dead band is found around the operating point, with the centred recording's width.
  ASSERT_FALSE(offset.verdict_blocks.empty());
  EXPECT_NEAR(offset.verdict_blocks[0].params[0], centred.verdict_blocks[0].params[0],
              0.1 * centred.verdict_blocks[0].params[0]);
  EXPECT_LT(offset.verdict_blocks[0].params[0], 5.0);
}

// A sensor that loses the sign (rectifies) is not in the vocabulary: a linear nominal cannot reach the
// noise floor, no block explains it, and the report says that the fit failed instead of naming an effect.
TEST(NominalStatus, AFitThatCannotReachTheNoiseIsReportedAsFailed) {
  ScenarioOptions so;
  so.seed = 7;
  so.samples = 900;
  Scenario sc = MakeScenario(so);
  for (auto* r : {&sc.ident, &sc.valid}) {
    const auto w = sc.linear_truth.simulate(r->u);
    for (std::size_t t = 0; t < w.size(); ++t) r->y[t] = std::abs(w[t]) + (r->y[t] - w[t]);
  }
  const NominalSpec spec = NominalSpec::Parse("linear:2,2");
  DiagnoseOptions o;
  o.threads = 1;
  o.noise_std = sc.noise_std;
  DiagnoseReport r;
  Diagnose(o, FitNominalForDiagnosis(spec, sc.ident, o).model, &spec, sc.ident, sc.valid, &r);
  ASSERT_TRUE(r.ok) << r.message;
  EXPECT_EQ(r.nominal_status, NominalStatus::kFailed) << r.message;
  EXPECT_EQ(r.verdict, Effect::kNone) << r.message;
  EXPECT_NE(r.message.find("nominal fit failed"), std::string::npos) << r.message;
}

// A handful of open-study scenarios (development seeds): no false alarm on the null cases, with the
// nominal given and fitted, and most of a few effects named.
TEST(OpenStudy, HandfulOfScenarios) {
  OpenStudyOptions o;
  o.rows = {{Effect::kBacklash, Location::kInput}, {Effect::kDelay, Location::kInput},
            {Effect::kQuantization, Location::kOutput}, {Effect::kCubicStiffness, Location::kState}};
  o.scenarios_per_row = 1;
  o.null_scenarios = 2;
  o.first_seed = 501;
  o.diagnose.threads = 1;
  const OpenStudyResult r = RunOpenStudy(o);
  std::cout << r.to_markdown("diagnose_open_study_test");
  int named = 0, effects = 0;
  for (const auto& c : r.cases) {
    if (c.row == "none") {
      EXPECT_EQ(c.verdict, "none") << NominalModeName(c.mode) << " seed " << c.seed;
    } else {
      ++effects;
      named += c.named_right;
    }
  }
  EXPECT_GE(named, effects * 5 / 8) << named << " of " << effects;
}

// A stopped run resumes: the scenarios an earlier run finished are taken from it (here a marked verdict, so a
// diagnosis run again would show), the others diagnosed, and the result is the whole run's.
TEST(OpenStudy, AStoppedRunResumesFromItsFinishedScenarios) {
  OpenStudyOptions o;
  o.rows = {{Effect::kBacklash, Location::kInput}};
  o.scenarios_per_row = 2;
  o.null_scenarios = 0;
  o.first_seed = 601;
  o.modes = {NominalMode::kGiven};
  o.diagnose.threads = 1;
  const OpenStudyResult whole = RunOpenStudy(o);
  ASSERT_EQ(whole.cases.size(), 2u);
  OpenStudyResult stopped = whole;
  stopped.cases.resize(1);
  stopped.cases[0].verdict = "taken from the earlier run";
  o.resume = &stopped;
  const OpenStudyResult resumed = RunOpenStudy(o);
  ASSERT_EQ(resumed.cases.size(), 2u);
  EXPECT_EQ(resumed.cases[0].verdict, "taken from the earlier run");
  EXPECT_EQ(resumed.cases[1].seed, whole.cases[1].seed);
  EXPECT_EQ(resumed.cases[1].verdict, whole.cases[1].verdict);
}

// A stiction scenario must show its stick-slip jump: when every input move is larger than the static
// band, stiction gives the same signal as backlash with the kinetic band as its play, and the scenario
// is backlash under another name. The generator sizes stiction by what neither the nominal nor backlash
// absorbs (noise-free); on these steps and PRBS seeds (retired range) backlash fitted the drawn stiction
// exactly (0.00 noise standard deviations left) before.
TEST(OpenScenario, StictionShowsWhatBacklashCannotDescribe) {
  for (unsigned seed : {700047u, 700263u, 700389u, 700425u}) {
    OpenScenarioOptions so;
    so.effect = Effect::kStiction;
    so.seed = seed;
    const OpenScenario sc = MakeOpenScenario(so);
    std::vector<double> u = sc.ident.u;
    for (auto& v : u) v -= sc.u_offset;
    const std::vector<double> y = sc.truth.simulate(u);
    const Segment all{&u, &y, 0, 0};
    const RefitResult backlash =
        AddBlock(sc.truth.WithoutBlocks(), Effect::kBacklash, Location::kInput, StateVariable::kPosition, all, RefitOptions{});
    EXPECT_GT(std::sqrt(backlash.sse / y.size()), 0.45 * sc.noise_std) << "seed " << seed;
  }
}

// An effect that the size search shrinks to nothing is no effect: in closed loop, stiction of any size can
// set off a stick-slip cycle larger than the target, and the search ended at bands of about 1e-12 of the
// input (retired seed). Such a draw is rejected and the scenario redrawn.
TEST(OpenScenario, AnEffectSizedToNothingIsRedrawn) {
  OpenScenarioOptions so;
  so.effect = Effect::kStiction;
  so.seed = 1400155;
  const OpenScenario sc = MakeOpenScenario(so);
  double mean = 0.0, var = 0.0;
  for (double v : sc.ident.u) mean += v / sc.ident.u.size();
  for (double v : sc.ident.u) var += (v - mean) * (v - mean) / sc.ident.u.size();
  ASSERT_EQ(sc.truth.blocks.size(), 1u);
  for (double band : sc.truth.blocks[0].params) EXPECT_GT(std::abs(band), 1e-6 * std::sqrt(var));
}

// Stick-slip (static band above the kinetic band) on a multisine: the stiction fit opens the jump from
// the backlash fit (equal bands) and ends below it in error; from its own grid, scored with the
// nominal's poles, it stayed at a small backlash-like band (development seed 3015).
// A stiction scenario's centred identification recording, its fitting part (the first two thirds) and
// the nominal refitted there: the base that stiction and backlash are added to.
struct StictionFittingPart {
  explicit StictionFittingPart(unsigned seed)
      : sc(MakeOpenScenario(StictionOptions(seed))), r(OperatingPoint::Of(sc.ident).Centred(sc.ident)),
        nfit(r.y.size() * 2 / 3), fit{&r.u, &r.y, 0, nfit} {
    AugmentedModel start = sc.nominal;
    start.output_offset = 0.0;
    base = RefitModel(start, fit, RefitOptions{}).model;
  }
  StictionFittingPart(const StictionFittingPart&) = delete;  // fit points into r
  static OpenScenarioOptions StictionOptions(unsigned seed) {
    OpenScenarioOptions so;
    so.effect = Effect::kStiction;
    so.seed = seed;
    return so;
  }
  RefitResult Add(Effect effect) const {
    return AddBlock(base, effect, Location::kInput, StateVariable::kPosition, fit, RefitOptions{});
  }
  OpenScenario sc;
  Recording r;
  std::size_t nfit;
  Segment fit;
  AugmentedModel base;
};

TEST(StictionFit, FindsTheStickSlipJumpThatBacklashCannotDescribe) {
  const StictionFittingPart part(3015);
  const RefitResult stiction = part.Add(Effect::kStiction);
  const RefitResult backlash = part.Add(Effect::kBacklash);
  ASSERT_EQ(stiction.model.blocks.size(), 1u);
  const auto& p = stiction.model.blocks[0].params;
  EXPECT_LT(p[1], 0.8 * p[0]) << "static " << p[0] << " kinetic " << p[1];
  EXPECT_LT(stiction.sse, 0.95 * backlash.sse);
}

// The bands are searched with the poles held and LM moves the poles with the bands held: development seed
// 1 501 425 (steps, linear:3,1,0, nominal given) stopped after one pass at bands (0.458, 0.158), held-out
// MSE 1.5x backlash's; alternating until the cost stops dropping brings it below half of backlash's.
TEST(StictionFit, BandsAndPolesAlternateUntilTheCostStopsDropping) {
  const StictionFittingPart part(1501425);
  const auto held_out_mse = [&](const AugmentedModel& m) {
    const std::vector<double> yhat = m.simulate(part.r.u);
    double sum = 0.0;
    for (std::size_t t = part.nfit; t < part.r.y.size(); ++t) sum += (part.r.y[t] - yhat[t]) * (part.r.y[t] - yhat[t]);
    return sum / static_cast<double>(part.r.y.size() - part.nfit);
  };
  const RefitResult stiction = part.Add(Effect::kStiction);
  const RefitResult backlash = part.Add(Effect::kBacklash);
  EXPECT_LT(held_out_mse(stiction.model), 0.5 * held_out_mse(backlash.model))
      << "static " << stiction.model.blocks[0].params[0] << " kinetic " << stiction.model.blocks[0].params[1];
}

// An open-study scenario diagnosed with its true nominal given, or with its structure fitted by the tool.
struct OpenDiagnosis {
  OpenScenario scenario;
  DiagnoseReport report;
};
OpenDiagnosis DiagnoseOpenScenario(const OpenScenarioOptions& so, bool fitted, DiagnoseOptions o = {}) {
  OpenDiagnosis d{MakeOpenScenario(so), {}};
  const OpenScenario& sc = d.scenario;
  o.threads = 1;
  if (fitted)
    Diagnose(o, FitNominalForDiagnosis(sc.structure, sc.ident, o).model, &sc.structure, sc.ident, sc.valid, &d.report);
  else
    Diagnose(o, sc.nominal, nullptr, sc.ident, sc.valid, &d.report);
  return d;
}

// The report on one scenario (effect, location, seed) diagnosed with its true nominal given, or fitted.
DiagnoseReport DiagnoseScenario(Effect effect, Location location, unsigned seed, bool fitted) {
  OpenScenarioOptions so;
  so.effect = effect;
  so.location = location;
  so.seed = seed;
  return DiagnoseOpenScenario(so, fitted).report;
}
DiagnoseReport DiagnoseWithNominalGiven(Effect effect, Location location, unsigned seed) {
  return DiagnoseScenario(effect, location, seed, /*fitted=*/false);
}
DiagnoseReport DiagnoseWithNominalFitted(Effect effect, Location location, unsigned seed) {
  return DiagnoseScenario(effect, location, seed, /*fitted=*/true);
}

// Whether the report names `effect` at `location` (its message otherwise).
::testing::AssertionResult Names(const DiagnoseReport& r, Effect effect, Location location) {
  if (r.ok && r.verdict == effect && r.verdict_location == location) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << r.message;
}

// The scenario of `seed` diagnosed with its nominal given names `effect` at `location`.
::testing::AssertionResult NamedWithNominalGiven(Effect effect, Location location, unsigned seed) {
  return Names(DiagnoseWithNominalGiven(effect, location, seed), effect, location);
}

// The scenario of `seed` names its input quantizer with the nominal given and with it fitted.
void ExpectInputQuantizerNamedWithEitherNominal(unsigned seed) {
  for (bool fitted : {false, true})
    EXPECT_TRUE(Names(DiagnoseScenario(Effect::kQuantization, Location::kInput, seed, fitted), Effect::kQuantization,
                      Location::kInput))
        << (fitted ? "fitted" : "given");
}

// A null recording whose fitted nominal stays stuck in a poor optimum (held-out RMSE 2.2x the noise): the
// refit of an input quantizer of a small step freed the nominal part under it, which alone (the block
// removed) reaches the noise, and was named as an effect. The blocks must make the difference, otherwise
// the fit failed (seed 500 252, from a retired reporting range, now development data). With every
// candidate, the refined stiction band search and the limits' fits from fresh nominal starts now carry the
// nominal part to the noise floor, and that part, refitted alone, replaces the baseline (verdict none, at
// the noise floor); the failed-fit path is checked without those candidates, where the nominal stays stuck
// as before.
TEST(NominalStatus, ABlockThatOnlyFreesAStuckNominalIsAFailedFitNotAnEffect) {
  OpenScenarioOptions so;
  so.effect = Effect::kNone;
  so.seed = 500252;
  DiagnoseOptions o;
  for (const auto& c : CandidateEffects())
    if (c.first != Effect::kStiction && c.first != Effect::kSaturation && c.first != Effect::kStateSaturation)
      o.candidates.push_back(c);
  const auto [sc, r] = DiagnoseOpenScenario(so, /*fitted=*/true, o);
  ASSERT_TRUE(r.ok) << r.message;
  EXPECT_GT(r.baseline_holdout_rmse, 1.2 * sc.noise_std);
  EXPECT_EQ(r.verdict, Effect::kNone) << r.message;
  EXPECT_EQ(r.nominal_status, NominalStatus::kFailed) << r.nominal_status_note;
  EXPECT_NE(r.nominal_status_note.find("poor optimum"), std::string::npos) << r.nominal_status_note;
}

// A relay on random steps: every threshold between two input levels predicts the identification
// recording alike, and the middle of that run (the fit's choice) switched on validation levels the
// device ignores (validation MSE 1.4-1.8x the baseline's, verdict none). Validation now judges the best
// threshold among those the identification recording cannot tell apart (retired seeds 700 080, 700 457).
TEST(OpenStudy, RelayThresholdUndeterminedByStepsIsJudgedAmongItsTies) {
  for (unsigned seed : {700080u, 700457u}) {
    OpenScenarioOptions so;
    so.effect = Effect::kHysteresis;
    so.seed = seed;
    const DiagnoseReport r = DiagnoseOpenScenario(so, /*fitted=*/false).report;
    ASSERT_TRUE(r.ok) << r.message;
    EXPECT_EQ(r.verdict, Effect::kHysteresis) << "seed " << seed << ": " << r.message;
  }
}

// A dead time against a richer numerator and pole: on retired seed 700 239 (multisine, linear:3,3,0,
// delay 4) the richer structure's held-out score was above the delay's by less than the noise (0.8889
// against 0.8887), so it replaced the baseline and the verdict was `none`; tied on the held-out tail,
// validation decides, where the delay is better. On retired seed 700 149 (steps, hw:3,2,1,3,0, delay
// 4, fitted nominal) the delay block started from the baseline stayed in the optimum whose numerator
// had absorbed part of the delay; the nominal structure with the delay added, fitted from fresh starts,
// leaves it.
TEST(OpenStudy, DelayTiedWithARicherNominalAndDelayFromFreshStarts) {
  for (const auto& [seed, fitted] : {std::pair{700239u, false}, std::pair{700149u, true}}) {
    OpenScenarioOptions so;
    so.effect = Effect::kDelay;
    so.seed = seed;
    const DiagnoseReport r = DiagnoseOpenScenario(so, fitted).report;
    ASSERT_TRUE(r.ok) << r.message;
    EXPECT_EQ(r.verdict, Effect::kDelay) << "seed " << seed << ": " << r.message;
  }
}

// A state saturation reached only in the fitting part of a closed-loop recording (retired seed 700 190,
// lower limit only): with it the nominal part is held at its true values, and without it that nominal
// part alone is at the noise on the held-out tail and on validation, where the limit is not reached, so
// the blocks seemed to make no difference and the fit was called failed (a poor optimum freed). On the
// fitting part they do: removing them there is significantly worse.
TEST(NominalStatus, ALimitReachedOnlyInTheFittingPartIsNeededThere) {
  const DiagnoseReport r = DiagnoseWithNominalGiven(Effect::kStateSaturation, Location::kState, 700190);
  ASSERT_TRUE(r.ok) << r.message;
  EXPECT_EQ(r.verdict, Effect::kStateSaturation) << r.message;
  EXPECT_EQ(r.nominal_status, NominalStatus::kExplainedByEffect) << r.nominal_status_note;
}

// A state saturation under a multisine whose baseline's cubic input map bent to imitate the limit
// (development seed 1 500 672, hw:3,3,3,1,2, nominal given): the limit block added to that baseline stayed
// in its basin (fitting-part cost 6.5x that of the nominal structure fitted from fresh starts with the
// block in place), explained too little of the excess, and the fit was called failed.
TEST(OpenStudy, LimitFromFreshStartsLeavesTheBentBaseline) {
  EXPECT_TRUE(NamedWithNominalGiven(Effect::kStateSaturation, Location::kState, 1500672));
}

// Named right on development seeds where the verdict used to be `none`: a delay that a richer numerator
// also absorbs (seed 1023: the delay, one parameter, competes with the richer nominal's two), and a
// backlash whose held-out tail shows nothing of it that the roles-swapped test (switched on here)
// confirms (seed 1019; stiction with equal bands, nearly the same curve, is not named instead).
TEST(OpenStudy, DelayAgainstARicherNumeratorAndEffectsOutsideTheHeldOutTail) {
  for (const auto& [effect, seed] : {std::pair{Effect::kDelay, 1023u}, std::pair{Effect::kBacklash, 1019u}}) {
    OpenScenarioOptions so;
    so.effect = effect;
    so.seed = seed;
    DiagnoseOptions o;
    o.swapped_min_improvement = 0.3;
    const DiagnoseReport r = DiagnoseOpenScenario(so, /*fitted=*/false, o).report;
    ASSERT_TRUE(r.ok) << r.message;
    EXPECT_EQ(r.verdict, effect) << "seed " << seed << ": " << r.message;
  }
}

// An input saturation on PRBS (retired seed 800 111, nominal given): every quantile of a two-level
// input is one of its levels, so no finite limit was tried, and hysteresis with a threshold never
// crossed (a constant input offset) was named instead.
TEST(OpenStudy, InputSaturationOnATwoLevelInput) {
  EXPECT_TRUE(NamedWithNominalGiven(Effect::kSaturation, Location::kInput, 800111));
}

// A relay in a closed loop (retired seed 800 314, linear:2,2,1): the reference steps make the input jump
// across a run of thresholds, all of which predict the fitting part alike; the middle of that run (the
// fit's choice) switched on moves in the held-out tail that the device ignores, the tail showed the
// relay worse than none (MSE 1.23x the baseline's) and the fit was called failed. The tail now judges
// the best threshold among those the fitting part cannot tell apart.
TEST(OpenStudy, RelayThresholdAmongTheFittingPartsTiesIsJudgedOnTheHeldOutTail) {
  EXPECT_TRUE(NamedWithNominalGiven(Effect::kHysteresis, Location::kInput, 800314));
}

// Stiction in a closed loop (retired seed 900 460, linear:1,1,2, nominal given): the coarse joint grid of
// the two bands had no pair close enough to the truth (0.298, 0.231) to cost less than the backlash start
// (every break-away a sample early or late), the fit stayed at (0.323, 0.226), and backlash was named.
// The best coarse pairs are now refined on finer grids of both bands.
TEST(StictionFit, BandsBetweenCoarseGridPointsAreRefined) {
  EXPECT_TRUE(NamedWithNominalGiven(Effect::kStiction, Location::kInput, 900460));
}

// Stiction whose identification recording never sticks and slips between the kinetic band and static
// bands up to 1.64 (retired seed 900 119, closed loop, nominal given): all those static bands predict it
// identically, the fit took the lowest (equal bands, backlash), and validation showed a stick-slip of
// 65 noise standard deviations that backlash leaves. Validation now judges the static band among the
// identification recording's ties.
TEST(OpenStudy, StaticBandAmongTheIdentificationTiesIsJudgedOnValidation) {
  EXPECT_TRUE(NamedWithNominalGiven(Effect::kStiction, Location::kInput, 900119));
}

// The same for a fit with a stick-slip jump: development seed 1 500 655 (steps, linear:3,1,0, nominal given),
// fitted static band 0.102 against the true 0.161, every band from 0.102 to 0.2 predicting the
// identification recording identically; at 0.102 the stem slips on validation's moves that the device
// ignores (validation MSE 17x the noise variance, above backlash's), at the true band validation is at the
// noise. Backlash was named; validation now judges the static band among the ties of a jump fit too.
TEST(OpenStudy, StaticBandOfAStickSlipFitAmongTheIdentificationTiesIsJudgedOnValidation) {
  EXPECT_TRUE(NamedWithNominalGiven(Effect::kStiction, Location::kInput, 1500655));
}

// Input quantizers on steps (retired seeds 1 000 114, linear:1,3,1, and 1 000 186, linear:3,3,0; nominal
// given): every step and grid offset that rounds the input samples alike predicts the identification
// recording alike once the numerator and offset are re-solved, and the fits' choices (0.1498 against the
// true 0.1501; 0.3631 and offset -0.037 against 0.3703 and 0) rounded validation's levels otherwise
// (validation MSE 0.88x and 0.80x the baseline's, not significant). Validation, and for 1 000 186 first
// the held-out tail, now judge the step and offset among those ties.
TEST(OpenStudy, InputQuantizerStepAndOffsetAmongTiesAreJudgedOnUnseenData) {
  for (unsigned seed : {1000114u, 1000186u})
    EXPECT_TRUE(Names(DiagnoseWithNominalGiven(Effect::kQuantization, Location::kInput, seed), Effect::kQuantization,
                      Location::kInput))
        << "seed " << seed;
}

// An output quantizer on PRBS (retired seed 1 000 302, hw:2,3,1,3,1, nominal given): the continuation
// that refits the nominal part under the quantizer, started at a quarter step's smoothing, stayed in a
// poorer optimum that mispredicted validation (MSE 1.12x the baseline's) while the held-out tail confirmed
// the quantizer; started at half a step, with a twentieth before the exact staircase, it reaches one
// validation confirms.
TEST(OpenStudy, OutputQuantizerContinuationStartsFromHalfAStep) {
  EXPECT_TRUE(NamedWithNominalGiven(Effect::kQuantization, Location::kOutput, 1000302));
}

// An output quantizer seen through few levels (development seed 1 500 856, PRBS, linear:2,2,1, nominal
// given): the fit found the step (0.398 against the true 0.399) and halved the held-out error, but stopped
// with a gain and offset before the quantizer that the identification recording cannot tell from the
// truth's and validation rejected (1.76x the baseline's error). The gains and offsets of the quantizer's
// argument that predict the identification recording alike are judged on validation.
TEST(OpenStudy, OutputQuantizerArgumentAmongTheIdentificationTiesIsJudgedOnValidation) {
  EXPECT_TRUE(NamedWithNominalGiven(Effect::kQuantization, Location::kOutput, 1500856));
}

// An output quantizer in closed loop (development seed 1 500 568, linear:2,2,0, nominal given): the levels
// read from the measured output gave the true step (0.110), but the step search, run with the baseline's
// numbers before the continuation refitted them, left it for 0.095, and the best fit ended at half the
// step with a grid offset between the true levels (held-out 0.76x, validation 0.72x, the nominal's fit
// reported as failed). Refitted under the levels as read first, the fit keeps the true step.
TEST(OpenStudy, OutputQuantizerLevelsReadFromTheDataAreHeldWhileTheNominalPartIsRefitted) {
  EXPECT_TRUE(NamedWithNominalGiven(Effect::kQuantization, Location::kOutput, 1500568));
}

// An output dead band at 0 on an output whose median is far from 0 (retired seed 1 100 174, filtered
// noise, hw:1,1,3,1,0 with a cubic input map, nominal given): the fit found the band (half-width 0.0144
// against the true 0.0145) and removed three quarters of the held-out error, but the band sat 0.25 of
// the output's 5-95 % spread from its median, beyond the quarter a band was allowed, and was rejected
// as physically meaningless (verdict none, fit failed). A fifth of the samples lie above the band and
// three quarters below it: the band sits inside the data, not at its edge like a clamp.
TEST(OpenStudy, DeadBandInsideASkewedSignalIsMeaningful) {
  EXPECT_TRUE(NamedWithNominalGiven(Effect::kDeadzone, Location::kOutput, 1100174));
}

// An output saturation reached in one stretch of the held-out tail (retired seed 1 100 049, multisine,
// hw:2,2,1,3,2, fitted nominal): the fit removed 88 % of the held-out error, and removing its block
// (nominal part kept) made the tail 16 times worse, but the two models differ only where the limit
// acts, within one batch, which gives the batch z exactly 1; rounding put it below 1, the block seemed
// not needed and the fit was called failed (verdict none).
TEST(NominalStatus, ALimitActingWithinOneBatchIsNeeded) {
  const DiagnoseReport r = DiagnoseWithNominalFitted(Effect::kSaturation, Location::kOutput, 1100049);
  EXPECT_TRUE(Names(r, Effect::kSaturation, Location::kOutput));
  EXPECT_EQ(r.nominal_status, NominalStatus::kExplainedByEffect) << r.nominal_status_note;
}

// A rate limit on steps under a quadratic output map (retired seed 1 200 004, hw:3,2,1,3,1, true limit
// 0.499 per sample): the baseline's poles absorbed the ramps, so the limit's grid points, scored with the
// baseline's numbers, ranked the mildest limits first (scores falling steadily with the limit); the three
// refined reached 1.75 at best, which explained a third of the excess, and the fit was called failed
// (verdict none). Refined from more grid points, the fit finds the limit (0.50).
TEST(OpenStudy, RateLimitGridPointsRankedByTheBaselineAreRefinedWellInsideTheJumps) {
  const DiagnoseReport r = DiagnoseWithNominalGiven(Effect::kRateLimit, Location::kInput, 1200004);
  ASSERT_TRUE(Names(r, Effect::kRateLimit, Location::kInput));
  EXPECT_NEAR(r.verdict_blocks.front().params[0], 0.499, 0.05);
}

// An input quantizer on steps under a cubic output map (retired seed 1 300 258, hw:3,3,1,3,1, nominal
// given): the held-out tail confirmed the quantizer (0.17x the baseline's) and validation did not (1.34x,
// step 0.1861): the search among the steps that round the identification recording's levels alike
// re-solved the numerator, which a non-identity output map does not allow, so none was tried. Scaling the
// grid and composing the input map with the inverse scaling predicts alike; validation judges the ties.
TEST(OpenStudy, InputQuantizerTiesUnderANonlinearMapAreJudgedOnValidation) {
  EXPECT_TRUE(NamedWithNominalGiven(Effect::kQuantization, Location::kInput, 1300258));
}

// An output quantizer under a cubic input map on a two-level input (retired seed 1 300 374, PRBS,
// hw:3,1,3,1,0): the identification recording fixes the map only at its two levels, the quantizer's
// fit carried the map's shape elsewhere with the same prediction, and validation, at other levels,
// rejected it (2.69x the baseline's error). The model with the baseline's map shape matched at the two
// levels predicts the identification recording alike, and validation judges the two.
TEST(OpenStudy, InputMapShapeLeftFreeByATwoLevelInputIsJudgedOnValidation) {
  EXPECT_TRUE(NamedWithNominalGiven(Effect::kQuantization, Location::kOutput, 1300374));
}

// The baseline refitted on such a recording moves the shape along the same freedom (development seed
// 1 501 874, PRBS, hw:3,3,3,1,2, an output quantizer, nominal given with the cubic's second coefficient
// 0.16): the baseline took it to 0.47 and the quantizer's fit kept it (held-out 0.18x the baseline's
// error, validation 1.41x, verdict none). The shape of the nominal as given is a second tie that
// validation judges (0.11x).
TEST(OpenStudy, InputMapShapeOfTheGivenNominalIsATieJudgedOnValidation) {
  EXPECT_TRUE(NamedWithNominalGiven(Effect::kQuantization, Location::kOutput, 1501874));
}

// The same freedom under any block the two-level input passes through unchanged (development seeds of
// 1 400 001-1 400 500, PRBS, nominal fitted): an output dead band (1 400 138, hw:3,3,3,1,2) moved the
// cubic's coefficients from (-0.476, -0.075) to (-0.437, -0.105), held-out 0.446x, validation 0.908x (not
// significant). With a dead time of 2 and 3 numerator terms, no initial state takes up the constant moved
// out of the map at the first samples exactly; the tie agrees with the model to a hundredth of the residual
// RMS there and exactly afterwards, and validation confirms the band (0.824x).
TEST(OpenStudy, InputMapShapeUnderAnOutputDeadBandIsJudgedOnValidation) {
  EXPECT_TRUE(Names(DiagnoseWithNominalFitted(Effect::kDeadzone, Location::kOutput, 1400138), Effect::kDeadzone,
                    Location::kOutput));
}

// A state saturation under a fitted cubic input map (development seed 1 400 172, PRBS, hw:3,1,3,1,1): the
// constant moved out of the map shifts the state by its steady-state response, and the limit shifted by
// as much gives the same prediction. The fit had moved the cubic's second coefficient from 0.206 to
// 0.282 (held-out 0.323x, validation 1.25x); with the baseline's shape validation confirms it (0.857x).
TEST(OpenStudy, InputMapShapeUnderAStateSaturationIsJudgedOnValidation) {
  EXPECT_TRUE(Names(DiagnoseWithNominalFitted(Effect::kStateSaturation, Location::kState, 1400172),
                    Effect::kStateSaturation, Location::kState));
}

// An input quantizer under a cubic input map on steps (retired seed 1 300 078, hw:3,3,3,1,2): the fitted
// grid (step 0.379, offset -0.1 step) and the true one (0.398, offset 0) put every identification sample
// on the same level index, and the cubic composed with the affine change between the grids predicts the
// recording alike; the search among ties reached only the steps within 3 % with the offset scaled along,
// and validation rejected the fit (1.95x the baseline's error). Both nominals.
TEST(OpenStudy, InputQuantizerGridsThatIndexTheSamplesAlikeAreJudgedOnValidation) {
  ExpectInputQuantizerNamedWithEitherNominal(1300078);
}

// An input dead band in a gap between two levels of a step input (retired seeds 1 300 200, hw:2,1,3,1,0,
// and 1 300 254, hw:2,1,3,1,2, nominal given): every centre that leaves the band in that gap predicts the
// identification recording alike (the samples outside the band are shifted by its half-width whatever its
// centre); the fit put the band at the far end of the gap (centres 0.569 and -0.227 against the true 0;
// where the fit stops on that run of ties depends on rounding, 0.342 for 1 300 254 on other machines),
// validation, with levels inside the gap, found it worse than none (2.71x, 1.31x) and the output dead band
// was named. Likewise in 1 300 128 (closed loop, hw:1,2,1,3,2), whose input jumps across the band (centre
// 0.272, validation 2.41x). Judged among the centres that predict the identification recording alike (to a
// tenth of its residual RMS), validation finds the band near 0.
TEST(OpenStudy, InputDeadBandCentreInAGapOfTheInputIsJudgedAmongItsTies) {
  for (unsigned seed : {1300200u, 1300254u, 1300128u})
    EXPECT_TRUE(Names(DiagnoseWithNominalGiven(Effect::kDeadzone, Location::kInput, seed), Effect::kDeadzone,
                      Location::kInput))
        << "seed " << seed;
}

// The fit on the fitting part can stop anywhere on the run of dead band centres that predict it exactly
// alike (retired seed 1 300 254, steps, nominal given: centre 0.342, half-width 0.105, held-out 4.31x the
// baseline's); the whole-recording refit from there ran off into a band outside the input (centre -9e4,
// half-width 0.006, not a device). The centre chosen among the fitting ties (-0.265, held-out 0.082x) is a
// second start of the whole-recording refit, which fits that recording better and validation confirms
// (0.32x, centre 0.091).
TEST(OpenStudy, WholeRecordingRefitAlsoStartsFromTheValueChosenAmongFittingTies) {
  const DiagnoseReport r = DiagnoseWithNominalGiven(Effect::kDeadzone, Location::kInput, 1300254);
  ASSERT_TRUE(r.ok) << r.message;
  const auto band = std::find_if(r.findings.begin(), r.findings.end(), [](const Finding& f) {
    return f.blocks.size() == 1 && f.blocks[0].effect == Effect::kDeadzone && f.blocks[0].location == Location::kInput;
  });
  ASSERT_NE(band, r.findings.end());
  EXPECT_TRUE(band->meaningful) << band->Label();
  EXPECT_TRUE(band->holdout.significant && band->validation.significant)
      << "held-out " << band->holdout.ratio << ", validation " << band->validation.ratio;
}

// An output saturation and a state saturation both eligible: ranked by the penalised scores alone, the
// state saturation came first in retired seed 1 300 067 (steps, hw:1,3,1,3,0, nominal given: scores 0.710
// against 0.710, held-out 0.155x against 0.219x, validation 0.525x against 0.395x). The output saturation's
// residual regressed on the difference of the two predictions on unseen data favours it by 2 standard
// errors; in 1 300 229 (filtered noise, linear:1,1,2) the two predict alike (0.256x / 0.261x held-out,
// 0.632x / 0.633x validation) and the report says they tie.
TEST(OpenStudy, OutputAndStateSaturationAreSettledByTheirPredictionDifference) {
  EXPECT_TRUE(NamedWithNominalGiven(Effect::kSaturation, Location::kOutput, 1300067));
  const DiagnoseReport r = DiagnoseWithNominalGiven(Effect::kSaturation, Location::kOutput, 1300229);
  ASSERT_FALSE(r.findings.empty());
  EXPECT_NE(r.findings.front().evidence.find("saturation@output and state_saturation@state tie"), std::string::npos)
      << r.findings.front().evidence;
}

// Retired seed 1 300 168 (steps, a cubic output map): the input quantizer's grid points, scored with the
// baseline's numerator, offset and initial state held (no least-squares re-solve under that map), put
// the true step's points at rank 285 of 1840, and the 12 refined ended at a step of 0.1205 (true 0.139);
// scored after the Gauss-Newton re-solve through the map, the true step's points rank first, and the
// best 3 so scored are refined besides the 12 (identification fit 0.454 against 0.977 on the fitting part).
TEST(OpenStudy, InputQuantizerGridUnderAPolynomialOutputMapIsScoredAfterAReSolveThroughTheMap) {
  ExpectInputQuantizerNamedWithEitherNominal(1300168);
}

// Development seed 1 500 114 (steps, hw:3,3,3,1,2, a cubic input map, true step 0.172): scored with the
// baseline's cubic map held, the input quantizer's grid points led the refined fits to a step of 0.1686 with
// the grid offset a tenth of a step off, whose fitting cost (1.89) stayed above that of a refit started at
// the true grid (1.68); the held-out tail (1.25x the baseline's) and validation (1.18x) rejected it and the
// nominal fit was reported failed. Scored after re-solving the map with the numerator, the grid points of
// the true grid (up to a scaling the map absorbs) rank among the best and the quantizer is named.
TEST(OpenStudy, InputQuantizerGridUnderAPolynomialInputMapIsScoredWithTheMapReSolved) {
  ExpectInputQuantizerNamedWithEitherNominal(1500114);
}

// Development seed 1 500 506 (steps, hw:1,3,1,3,0, a cubic output map, true step 0.442): ranked with the
// baseline's numbers, the grid points at the true step came 56th and lower, and the 15 refined points all
// sat at steps of 0.06-0.25 or 0.48 (the best refined fit 0.232, fitting cost 2.65 against 2.35 from the
// true step); the held-out tail (1.02x) and validation (1.52x) rejected it and the nominal fit was reported
// failed. With the best point of every band of steps a factor 1.5 wide refined too, the refined fits
// reach the true step's cost and the quantizer is named.
TEST(OpenStudy, InputQuantizerRefinesTheBestGridPointOfEveryBandOfSteps) {
  ExpectInputQuantizerNamedWithEitherNominal(1500506);
}

// Development seed 1 500 402 (closed loop, an input quantizer): the refined fits stopped beside the true
// step and grid offset, whose optimum is narrow in both jointly, and neither the held-out tail nor
// validation confirmed the quantizer (the nominal fit was reported failed). Refitted by continuation
// (rounding smoothed over a quarter of a step down to a fiftieth, step and grid offset moved with every
// other number), the fit reaches it and the quantizer is named.
TEST(OpenStudy, InputQuantizerStepAndOffsetAreRefittedWithTheRoundingSmoothed) {
  ExpectInputQuantizerNamedWithEitherNominal(1500402);
}

// An output dead band on a PRBS response (retired seed 1 400 461, linear:3,3,2, half-width 0.197, 9.6 noise
// standard deviations): the output crosses the band quickly, so the cost has many local optima in the
// band's centre and width; the refined grid points stopped at a centre 0.25 from the true one (2.3 times
// the true band's fitting cost), validation found that fit 12 times the noise's mean square, a richer
// linear nominal beat it there and replaced the baseline, and no effect was named. Scanned through the
// band (numerator, offset and initial state re-solved), the fit reaches the true band.
TEST(OpenStudy, OutputDeadBandCentreAndWidthAreScannedThroughTheBand) {
  const DiagnoseReport r = DiagnoseWithNominalGiven(Effect::kDeadzone, Location::kOutput, 1400461);
  ASSERT_TRUE(Names(r, Effect::kDeadzone, Location::kOutput));
  EXPECT_NEAR(r.verdict_blocks.front().params[0], 0.197, 0.01);
}

// A two-sided output saturation on PRBS (retired seed 1 400 193, hw:1,1,1,3,2, nominal given) whose lower
// limit is reached only in the held-out tail and on validation: fitted on the fitting part, the upper limit
// alone won; refitted on the whole recording with that one limit, validation was 1.27x the baseline's and the
// state saturation (both limits) was named. Refitted on the whole recording with both limits as well, the
// lower limit lowers the penalised cost there, validation confirms the output saturation, and the prediction
// difference ranks it above the state saturation.
TEST(OpenStudy, ALimitReachedOnlyAfterTheFittingPartIsFittedOnTheWholeRecording) {
  const DiagnoseReport r = DiagnoseWithNominalGiven(Effect::kSaturation, Location::kOutput, 1400193);
  ASSERT_TRUE(Names(r, Effect::kSaturation, Location::kOutput));
  EXPECT_TRUE(std::isfinite(r.verdict_blocks.front().params[0]) && std::isfinite(r.verdict_blocks.front().params[1]));
}

// An upper output saturation on steps (retired seed 1 400 479, hw:2,3,1,3,1, nominal given): on the fitting
// part a second, lower limit clipped the lowest step level by a hair and won the held-out score; validation,
// with lower levels, was 25x the baseline's error and no effect was named. Refitted on the whole recording
// with one and with both limits, the upper limit alone has the lower penalised cost there, and validation
// confirms it.
TEST(OpenStudy, ASecondLimitIsKeptOnlyWhereItLowersThePenalisedCostOfTheWholeRecording) {
  const DiagnoseReport r = DiagnoseWithNominalGiven(Effect::kSaturation, Location::kOutput, 1400479);
  ASSERT_TRUE(Names(r, Effect::kSaturation, Location::kOutput));
  EXPECT_FALSE(std::isfinite(r.verdict_blocks.front().params[0]));
}

// The same recording with the output dead band as the only candidate: fitted on the fitting part it is a
// narrow band in the middle of the output, refitted on the whole recording a band centred at the
// saturation's limit (a clamp, not a dead band). The named fit must describe a device too.
TEST(OpenStudy, TheFitOnTheWholeRecordingMustBePhysicallyMeaningfulToo) {
  OpenScenarioOptions so;
  so.effect = Effect::kSaturation;
  so.location = Location::kOutput;
  so.seed = 1400479;
  DiagnoseOptions o;
  o.candidates = {{Effect::kDeadzone, Location::kOutput}};
  const DiagnoseReport r = DiagnoseOpenScenario(so, /*fitted=*/false, o).report;
  EXPECT_EQ(r.verdict, Effect::kNone) << r.message;
}

// A lower output limit the fitting part never reaches (development seed 1 500 409, PRBS, hw:2,3,1,3,2,
// nominal given): the fitting part's lowest prediction lies 0.0004 above it, the held-out tail and
// validation reach 0.07 below it. Fitted there, the output saturation placed nothing (1x the baseline's
// error on both tests) and the state saturation, clipping the fitting part by a hair, was named. Its
// whole-recording refit restarted from the grid places the limit (-0.477 against the true -0.4777),
// validation confirms it (0.031x) and the roles-swapped test stands in for the tail; ranked against the
// state saturation by their prediction difference on validation only (the output saturation's fit on
// the fitting part, which never placed its limit, has the baseline's residual on the tail).
TEST(OpenStudy, ALimitTheFittingPartNeverReachesIsPlacedOnTheWholeRecording) {
  const DiagnoseReport r = DiagnoseWithNominalGiven(Effect::kSaturation, Location::kOutput, 1500409);
  ASSERT_TRUE(Names(r, Effect::kSaturation, Location::kOutput)) << r.message;
  EXPECT_NEAR(r.verdict_blocks.front().params[0], -0.4777, 0.01);
  EXPECT_TRUE(r.findings.front().swapped_stands_in);
}

// A pair that beats its first block but not, on validation, its second block alone names the second alone.
// Retired seed 1 500 317 (closed loop, linear:2,3,0): backlash ranked first (tied with stiction on the
// prediction difference), and backlash + stiction beat backlash; against stiction alone the pair gains
// nothing on validation (MSE 0.978x, z = 1.1), stiction with equal bands being backlash already. Retired
// seed 1 500 020 (closed loop, hw:1,3,1,3,0): an output dead band ranked first on the roles-swapped test,
// and the pair with the input dead band predicts validation exactly as the input dead band alone.
TEST(OpenStudy, APairNoBetterThanItsSecondBlockAloneNamesThatBlockAlone) {
  const DiagnoseReport stiction = DiagnoseWithNominalGiven(Effect::kStiction, Location::kInput, 1500317);
  EXPECT_TRUE(Names(stiction, Effect::kStiction, Location::kInput));
  EXPECT_EQ(stiction.verdict_blocks.size(), 1u) << stiction.message;
  const DiagnoseReport dead_band = DiagnoseWithNominalGiven(Effect::kDeadzone, Location::kInput, 1500020);
  EXPECT_TRUE(Names(dead_band, Effect::kDeadzone, Location::kInput));
  EXPECT_EQ(dead_band.verdict_blocks.size(), 1u) << dead_band.message;
}

// The partner alone is also fitted from the pair's numbers: in development seed 1 501 010 (steps,
// hw:3,3,1,3,0, a two-sided state saturation) the state saturation fitted alone kept one limit (validation
// MSE 0.177x the baseline's) and the output saturation was ranked first; the pair found the second state
// limit, and the output saturation in it clipped almost nothing the state limits leave. Refitted from the
// pair's numbers (the whole identification recording's cost lower), the state saturation alone predicts
// validation as the pair does (0.042x), and it is named alone.
TEST(OpenStudy, APairsNumbersForItsSecondBlockAreAStartOfThatBlockAlone) {
  for (bool fitted : {false, true}) {
    const DiagnoseReport r = DiagnoseScenario(Effect::kStateSaturation, Location::kState, 1501010, fitted);
    EXPECT_TRUE(Names(r, Effect::kStateSaturation, Location::kState)) << (fitted ? "fitted" : "given");
    EXPECT_EQ(r.verdict_blocks.size(), 1u) << r.message;
  }
}

// The held-out tail does not decide it: in retired seed 1 400 298 (fitted nominal) the state saturation +
// output saturation pair is no better than the output saturation alone on the held-out tail (0.825x,
// z = 0.6) and far better on validation (0.094x, z = 2.1); the pair, led by the true state saturation, stays.
TEST(OpenStudy, APairBetterThanItsSecondBlockAloneOnValidationStays) {
  const DiagnoseReport r = DiagnoseWithNominalFitted(Effect::kStateSaturation, Location::kState, 1400298);
  EXPECT_TRUE(Names(r, Effect::kStateSaturation, Location::kState));
}

// An output and a state saturation that tie on unseen data: development seed 1 500 976 (multisine,
// hw:2,2,3,1,2, state saturation) never reaches the limit on validation, and the clipping episode after
// which the two differ most lies in the fitting part: on unseen data they differ mostly by their nominal
// parts' estimation errors (coefficient 0.23, z = -1.1), and the penalised scores (0.8762 against 0.8754)
// named the output saturation. On the identification recording the output leaving the limit follows the
// clipped state (whole-recording error 0.051 against 0.066), and that fit decided the tie. With the limits
// also fitted from fresh nominal starts and the whole-recording refits also started from the baseline's
// refit there, the state saturation predicts validation at 0.106x the baseline's error and ranks first
// without the tie; the verdict is what is checked.
TEST(OpenStudy, OutputAndStateSaturationTiedOnUnseenDataAreSettledOnTheIdentificationRecording) {
  const DiagnoseReport r = DiagnoseWithNominalGiven(Effect::kStateSaturation, Location::kState, 1500976);
  EXPECT_TRUE(Names(r, Effect::kStateSaturation, Location::kState)) << r.findings.front().evidence;
}

// The held-out tail compares the two saturations only where both fits on the fitting part placed their
// limit: in development seed 1 500 657 (filtered noise, hw:1,2,3,1,0, output saturation) the fitting part
// reaches the limit by a hair; the output saturation's fit there left its limit at -7.83, below every value
// (the baseline on the tail), the state saturation's at -6.53, and the tail's clipping episode favoured the
// state saturation by 8.6 standard errors. Validation alone favours the output saturation (z = 2.7).
TEST(OpenStudy, ALimitTheFittingPartFitNeverPlacedDoesNotJudgeTheTail) {
  EXPECT_TRUE(NamedWithNominalGiven(Effect::kSaturation, Location::kOutput, 1500657));
}

// An output dead band whose input never passes beyond its lower edge is a lower output saturation with its
// offset moved by the half-width, one parameter more. Development seed 1 500 996 (multisine, hw:3,1,1,3,0,
// output saturation): the band (centre -0.903, half-width 0.696) sat at the bottom of a skewed output
// whose median lies within a quarter of the spread of its centre, so the median test called it central,
// and it was named (validation 0.627x against the saturation's 0.662x).
TEST(OpenStudy, AnOutputDeadBandPassedOnOneSideOnlyIsAClamp) {
  const DiagnoseReport r = DiagnoseWithNominalGiven(Effect::kSaturation, Location::kOutput, 1500996);
  EXPECT_TRUE(Names(r, Effect::kSaturation, Location::kOutput));
  const auto band = std::find_if(r.findings.begin(), r.findings.end(), [](const Finding& f) {
    return f.blocks.size() == 1 && f.blocks[0].effect == Effect::kDeadzone && f.blocks[0].location == Location::kOutput;
  });
  ASSERT_NE(band, r.findings.end());
  EXPECT_FALSE(band->meaningful) << band->evidence;
}

// Development seed 1 501 686 (steps, linear:3,3,2, true step 0.434, grid offset 0): the input quantizer's fit
// on the fitting part put the grid offset a tenth of a step above 0 instead of below it; both round every
// fitting sample alike, but one level of the held-out tail sits a twentieth of a step from a rounding edge,
// and the fit was 1.33x the baseline's there while an output quantizer was named. A shifted grid offset
// moves the quantized input by a constant, whose start-up transient (before nb + delay samples) no initial
// state matches exactly, so the tie search rejected every offset; compared from the first sample at which
// the constant has fully entered, the offsets are ties and the held-out tail chooses among them.
TEST(OpenStudy, InputQuantizerOffsetTiesUnderALinearNominalAreComparedAfterTheConstantHasEntered) {
  ExpectInputQuantizerNamedWithEitherNominal(1501686);
}

// Development seed 1 501 664 (steps, linear:1,3,2, nominal given): the input dead band's fit on the fitting
// part put its centre at -0.148 (true 0), where no fitting level tells it apart, and its whole-recording refit
// started from there stopped at a cost of 9.39 while the band's own grid on the whole recording reaches the
// true band at 8.85. Both tests confirmed it, so no restart was tried, and the output dead band (validation
// 0.574x against 0.659x) was named. The whole-recording refit is restarted from the grid whenever the held-out
// tail confirms the candidate (validation 0.549x) and the input dead band is named.
TEST(OpenStudy, WholeRecordingRefitIsRestartedFromTheGridWhenBothTestsConfirm) {
  EXPECT_TRUE(NamedWithNominalGiven(Effect::kDeadzone, Location::kInput, 1501664));
}

// Development seed 1 501 538 (steps, hw:1,2,3,1,1 with an operating point, nominal fitted): the cubic input
// map fitted with the dead band on the fitting part extrapolates poorly to the rest of the recording, and
// the whole-recording refit started from that fit stopped at a cost of 28.6, five times the baseline's own
// refit there (validation 2.41x the baseline's); an output dead band was named. Started also from the
// baseline's whole-recording refit with the band's fitted numbers, the refit reaches 3.49, validation
// confirms the band (0.458x) and it is named.
TEST(OpenStudy, WholeRecordingRefitAlsoStartsFromTheBaselinesRefitThere) {
  EXPECT_TRUE(Names(DiagnoseWithNominalFitted(Effect::kDeadzone, Location::kInput, 1501538), Effect::kDeadzone,
                    Location::kInput));
}

}  // namespace
}  // namespace hw::diagnose
