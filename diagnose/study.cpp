#include "diagnose/study.hpp"

#include <algorithm>
#include <chrono>

#include <fmt/format.h>

#include "core/input_error.hpp"
#include "diagnose/locate.hpp"

namespace hw::diagnose {

bool StudyOptions::IsValid(std::string* error) const {
  if (seeds_per_effect < 0 || null_scenarios < 0 || ratios.empty() || samples < 200) {
    if (error) *error = "study needs seeds >= 0, null scenarios >= 0, ratios non-empty, samples >= 200";
    return false;
  }
  return diagnose.IsValid(error);
}

StudyResult RunStudy(const StudyOptions& o) {
  std::string err;
  if (!o.IsValid(&err)) throw InputError("study: " + err);
  const auto t0 = std::chrono::steady_clock::now();
  auto effects = o.effects;
  if (effects.empty()) {
    for (const auto& n : EffectVocabulary())
      if (n != "none") effects.emplace_back(ParseEffect(n), DefaultLocation(ParseEffect(n)));
    for (Effect e : {Effect::kDeadzone, Effect::kSaturation, Effect::kQuantization}) effects.emplace_back(e, Location::kOutput);
  }
  StudyResult res;
  for (const auto& n : EffectVocabulary())
    if (n != "none") res.labels.push_back(n);
  res.labels.push_back("none");
  for (const auto& [e, l] : effects) res.rows.push_back(EffectName(e) + "@" + LocationName(l));
  res.rows.push_back("none");
  const bool design = o.nominal == "design";
  const NominalSpec spec = design ? NominalSpec{} : NominalSpec::Parse(o.nominal);
  auto run = [&](Effect effect, Location location, std::size_t row, unsigned seed, double ratio) {
    ScenarioOptions so;
    so.effect = effect;
    so.location = static_cast<int>(location);
    so.seed = seed;
    so.samples = o.samples;
    so.effect_rms_ratio = ratio;
    const Scenario sc = MakeScenario(so);
    const Segment seg{&sc.ident.u, &sc.ident.y, o.diagnose.init_samples, 0};
    const AugmentedModel nominal = design ? AugmentedModel{sc.linear_truth, {}, 0.0, {}}
                                          : FitNominal(spec, seg, o.diagnose.nominal_fit).model;
    DiagnoseReport r;
    Diagnose(o.diagnose, nominal, design ? nullptr : &spec, sc.ident, sc.valid, &r);
    StudyCase c;
    c.truth = effect;
    c.truth_location = sc.truth.has_block() ? sc.truth.blocks.front().location : Location::kInput;
    c.seed = seed;
    c.ratio = ratio;
    c.verdict = r.verdict;
    c.verdict_location = r.verdict_location;
    c.verdict_label = r.verdict == Effect::kNone ? "none" : r.augmented_model.Label();
    c.fit_nominal = r.nominal_refit.fit_percent;
    c.rmse_nominal = r.nominal_refit.rmse;
    c.fit_augmented = r.augmented.fit_percent;
    c.rmse_augmented = r.augmented.rmse;
    std::size_t both = 0;
    for (std::size_t t = 0; t < r.mask.size(); ++t) {
      c.flagged += r.mask[t];
      c.active += sc.ident_active[t];
      both += r.mask[t] && sc.ident_active[t];
    }
    c.window_precision = c.flagged ? double(both) / c.flagged : 0.0;
    c.window_recall = c.active ? double(both) / c.active : 0.0;
    c.window_iou = IntersectionOverUnion(r.mask, sc.ident_active, o.diagnose.init_samples);
    c.seconds = r.seconds;
    c.row = row;
    res.cases.push_back(c);
  };
  for (std::size_t i = 0; i < effects.size(); ++i)
    for (int s = 0; s < o.seeds_per_effect; ++s)
      run(effects[i].first, effects[i].second, i, o.first_seed + s, o.ratios[s % o.ratios.size()]);
  for (int s = 0; s < o.null_scenarios; ++s)
    run(Effect::kNone, Location::kInput, effects.size(), o.first_seed + s, o.ratios[s % o.ratios.size()]);

  const std::size_t k = res.labels.size();
  res.confusion.assign(res.rows.size(), std::vector<int>(k, 0));
  auto index = [&](Effect e) {
    const auto it = std::find(res.labels.begin(), res.labels.end(), EffectName(e));
    return it == res.labels.end() ? k - 1 : static_cast<std::size_t>(it - res.labels.begin());
  };
  int correct = 0, located = 0, detected_right = 0, with_effect = 0, named_right = 0, named_right_iou_n = 0;
  double prec = 0.0, rec = 0.0, gain = 0.0, iou = 0.0, iou_right = 0.0, null_flagged = 0.0;
  for (const auto& c : res.cases) {
    ++res.confusion[c.row][index(c.verdict)];
    correct += c.truth == c.verdict;
    if (c.truth == Effect::kNone) {
      ++res.null_cases;
      res.false_alarms += c.verdict != Effect::kNone;
      null_flagged += c.flagged / static_cast<double>(std::max<std::size_t>(1, o.samples - o.diagnose.init_samples));
      continue;
    }
    ++with_effect;
    prec += c.window_precision;
    rec += c.window_recall;
    gain += c.fit_augmented - c.fit_nominal;
    iou += c.window_iou;
    if (c.truth == c.verdict) {
      ++detected_right;
      located += c.truth_location == c.verdict_location;
      if (c.truth_location == c.verdict_location) ++named_right, iou_right += c.window_iou, ++named_right_iou_n;
    }
  }
  res.accuracy = res.cases.empty() ? 0.0 : double(correct) / res.cases.size();
  res.false_alarm_rate = res.null_cases ? double(res.false_alarms) / res.null_cases : 0.0;
  res.location_accuracy = detected_right ? double(located) / detected_right : 0.0;
  res.named_right_rate = with_effect ? double(named_right) / with_effect : 0.0;
  res.mean_window_precision = with_effect ? prec / with_effect : 0.0;
  res.mean_window_recall = with_effect ? rec / with_effect : 0.0;
  res.mean_fit_gain = with_effect ? gain / with_effect : 0.0;
  res.mean_window_iou = with_effect ? iou / with_effect : 0.0;
  res.mean_window_iou_named_right = named_right_iou_n ? iou_right / named_right_iou_n : 0.0;
  res.mean_null_flagged_fraction = res.null_cases ? null_flagged / res.null_cases : 0.0;
  res.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return res;
}

nlohmann::json StudyResult::to_json() const {
  nlohmann::json cs = nlohmann::json::array();
  for (const auto& c : cases)
    cs.push_back({{"truth", EffectName(c.truth)},
                  {"truth_location", c.truth == Effect::kNone ? "none" : LocationName(c.truth_location)},
                  {"verdict", EffectName(c.verdict)},
                  {"verdict_location", c.verdict == Effect::kNone ? "none" : LocationName(c.verdict_location)},
                  {"seed", c.seed},
                  {"effect_rms_ratio", c.ratio},
                  {"validation_fit_nominal", c.fit_nominal},
                  {"validation_fit_augmented", c.fit_augmented},
                  {"validation_rmse_nominal", c.rmse_nominal},
                  {"validation_rmse_augmented", c.rmse_augmented},
                  {"verdict_label", c.verdict_label},
                  {"window_iou", c.window_iou},
                  {"window_precision", c.window_precision},
                  {"window_recall", c.window_recall},
                  {"flagged_samples", c.flagged},
                  {"active_samples", c.active},
                  {"seconds", c.seconds}});
  return {{"rows", rows},
          {"labels", labels},
          {"confusion", confusion},
          {"accuracy", accuracy},
          {"false_alarm_rate", false_alarm_rate},
          {"location_accuracy", location_accuracy},
          {"named_right_rate", named_right_rate},
          {"false_alarms", false_alarms},
          {"null_cases", null_cases},
          {"mean_window_iou", mean_window_iou},
          {"mean_window_iou_named_right", mean_window_iou_named_right},
          {"mean_null_flagged_fraction", mean_null_flagged_fraction},
          {"mean_window_precision", mean_window_precision},
          {"mean_window_recall", mean_window_recall},
          {"mean_validation_fit_gain", mean_fit_gain},
          {"seconds", seconds},
          {"cases", cs}};
}

std::string StudyResult::to_markdown() const {
  std::string s = "| true \\ verdict |";
  for (const auto& l : labels) s += " " + l + " |";
  s += "\n|---|";
  for (std::size_t i = 0; i < labels.size(); ++i) s += "---|";
  s += "\n";
  for (std::size_t i = 0; i < rows.size(); ++i) {
    s += "| " + rows[i] + " |";
    for (int v : confusion[i]) s += v ? fmt::format(" **{}** |", v) : " · |";
    s += "\n";
  }
  s += fmt::format(
      "\nScenarios: {} ({} with an effect, {} null). Effect named right (name and location): {:.1f} %; false alarms: "
      "{} of {} null scenarios (mean flagged fraction there {:.2f} %); accuracy over all scenarios {:.1f} %; location "
      "correct in {:.1f} % of the correctly named effects. Windows vs the samples where the effect moves the output by "
      "more than the noise: mean IoU {:.2f} over all effect scenarios ({:.2f} over those named right), precision "
      "{:.2f}, recall {:.2f}. Mean validation fit gain {:+.2f} points; run time {:.1f} s ({:.2f} s per scenario).\n",
      cases.size(), cases.size() - null_cases, null_cases, 100 * named_right_rate, false_alarms, null_cases,
      100 * mean_null_flagged_fraction, 100 * accuracy, 100 * location_accuracy, mean_window_iou,
      mean_window_iou_named_right, mean_window_precision, mean_window_recall, mean_fit_gain, seconds,
      cases.empty() ? 0.0 : seconds / cases.size());
  return s;
}

}  // namespace hw::diagnose
