#pragma once
// Experiment plans for Brouri's method and their recordings.
//   Stage 1 ("steps"): reset hold, ascending holds, descending holds, all `hold_samples` long: the first
//     hold_samples - M samples let the transient of G die (settling time given by the user), the last M
//     are averaged (eq. 9).
//   Stage 2 ("sines"): per frequency, z = U sin(omega t) sampled with an integer number of samples per
//     period; the input to apply is u = precompensator(z) built from the stage-1 estimate. The first
//     `transient_periods` periods (>= the settling time) are discarded, the next N averaged (eq. 23).
// Recordings are CSV (or .mat, core/recording.hpp) files with columns u (as applied) and y (measured); a t
// column, when present, is checked against the planned sample time.
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/csv_table.hpp"
#include "estimators/brouri/frequency_stage.hpp"
#include "estimators/brouri/nonlinear_stage.hpp"

namespace hw::brouri {

struct StepPlan {
  double sample_time = 0.5;
  int hold_samples = 260;
  int average_samples = 100;  // M
  double reset_level = -1.0;
  std::vector<double> levels_up, levels_down;
  std::string file = "steps.csv";

  bool IsValid(std::string* error) const;
  std::vector<double> Levels() const;  // reset, ascending, descending
  std::vector<double> Input() const;   // one value per sample
  nlohmann::json to_json() const;
  static StepPlan from_json(const nlohmann::json& j);
};
// Hold = ceil(settling_time / sample_time) + M samples.
StepPlan MakeStepPlan(std::vector<double> levels_up, std::vector<double> levels_down, double reset_level,
                      double sample_time, double settling_time, int average_samples);

struct SineExperiment {
  double omega = 0.1;
  int samples_per_period = 512;
  int transient_periods = 1;
  int periods = 50;  // N
  std::string file;
  double sample_time() const;
  int total_samples() const { return samples_per_period * (transient_periods + periods); }
};

struct SinePlan {
  double amplitude = 1.0;
  std::vector<SineExperiment> experiments;
  NonlinearEstimate nonlinear;  // the stage-1 estimate the pre-compensator is built from

  bool IsValid(std::string* error) const;
  std::vector<double> Command(std::size_t i) const;  // z
  std::vector<double> Input(std::size_t i) const;    // u = precompensator(z)
  nlohmann::json to_json() const;
  static SinePlan from_json(const nlohmann::json& j);
};
SinePlan MakeSinePlan(const NonlinearEstimate& nonlinear, const std::vector<double>& omegas, double amplitude,
                      int samples_per_period, int periods, double settling_time);

// The stage of a plan ("steps" or "sines"); InputError naming `source` (the plan's file, or "plan") when the JSON is
// not a brouri plan. The CLI and the Python module read plans through it.
std::string PlanStage(const nlohmann::json& plan, const std::string& source);

// Estimation from recordings (u may be empty to skip the check that it matches the plan).
NonlinearEstimate EstimateFromSteps(const StepPlan& plan, const NonlinearOptions& options,
                                    const std::vector<double>& u, const std::vector<double>& y, Summary* summary);
FrequencyPoint EstimateFromSine(const SinePlan& plan, std::size_t i, const FrequencyOptions& options,
                                const std::vector<double>& u, const std::vector<double>& y, Summary* summary);

// Reads a recording (core/recording.hpp: a CSV, or FILE.mat:y=VAR[,u=VAR,t=VAR]; column y_col, optional u and t)
// and checks its time column against the planned sample time.
struct Recording {
  std::vector<double> u, y;
};
Recording ReadRecording(const std::string& path, double sample_time, const std::string& y_col);
// The same checks on a recording already read (columns y_col, optional u and t; messages name t.source).
Recording CheckRecording(const CsvTable& t, double sample_time, const std::string& y_col);

// The result JSON `hwbounds brouri estimate` writes for each stage (points unwrapped by the caller).
nlohmann::json StepsResultJson(const NonlinearEstimate& estimate, const Summary& summary);
nlohmann::json SinesResultJson(const SinePlan& plan, const std::vector<FrequencyPoint>& points);

}  // namespace hw::brouri
