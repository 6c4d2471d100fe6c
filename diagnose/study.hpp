#pragma once
// The concealed-effect study: generate scenarios (scenario.hpp) for every effect and for the null case,
// fit the nominal linear model, diagnose, and score the verdicts (confusion matrix, false-alarm rate,
// location accuracy, overlap of the mismatch windows with the samples where the effect is active,
// validation fit gain). Used by tests/diagnose_test.cpp (small set) and paper_examples/diagnose_study.cpp.
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "diagnose/diagnose.hpp"
#include "diagnose/scenario.hpp"

namespace hw::diagnose {

struct StudyOptions {
  // Concealed effects and their locations; empty = every effect at its usual location plus
  // deadzone, saturation and quantization at the output.
  std::vector<std::pair<Effect, Location>> effects;
  int seeds_per_effect = 3;
  int null_scenarios = 3;
  std::size_t samples = 1500;        // per recording
  std::vector<double> ratios = {1.5, 2.25, 3.0};  // effect RMS / noise std, cycled over seeds
  // Nominal model: a structure fitted on the identification recording ("linear:2,2", "hw:2,2,3,3"),
  // or "design": the true nominal handed over as a model from design (as with --model).
  std::string nominal = "linear:2,2";
  unsigned first_seed = 1;
  DiagnoseOptions diagnose;
  bool IsValid(std::string* error) const;
};

struct StudyCase {
  Effect truth = Effect::kNone, verdict = Effect::kNone;
  Location truth_location = Location::kInput, verdict_location = Location::kInput;
  unsigned seed = 0;
  double ratio = 0.0;
  double fit_nominal = 0.0, fit_augmented = 0.0;  // validation fit %, best nominal vs augmented
  double rmse_nominal = 0.0, rmse_augmented = 0.0;
  double window_precision = 0.0, window_recall = 0.0;  // flagged vs truly active samples
  double window_iou = 0.0;  // |flagged and active| / |flagged or active| (1 when both are empty)
  std::size_t flagged = 0, active = 0;
  std::string verdict_label;  // e.g. "backlash@input" or a combination "a@input+b@state"
  std::size_t row = 0;  // row of the confusion matrix
  double seconds = 0.0;
};

struct StudyResult {
  std::vector<StudyCase> cases;
  std::vector<std::string> rows;                  // true effect@location, then none
  std::vector<std::string> labels;                // verdict columns: effect names, then none
  std::vector<std::vector<int>> confusion;        // [row][verdict]
  double accuracy = 0.0, false_alarm_rate = 0.0, location_accuracy = 0.0;
  double named_right_rate = 0.0;         // effect scenarios whose verdict names the effect and its location
  int false_alarms = 0, null_cases = 0;
  double mean_window_precision = 0.0, mean_window_recall = 0.0, mean_fit_gain = 0.0, seconds = 0.0;
  double mean_window_iou = 0.0;          // over effect scenarios
  double mean_window_iou_named_right = 0.0;
  double mean_null_flagged_fraction = 0.0;
  nlohmann::json to_json() const;
  std::string to_markdown() const;
};

StudyResult RunStudy(const StudyOptions& options);

}  // namespace hw::diagnose
