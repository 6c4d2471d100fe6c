#pragma once
// Discrepancy diagnosis: where does a nominal model's simulation differ from a recording, which
// physical effect did it leave out, and does inserting that effect improve held-out data?
//
// Procedure (Diagnose):
//  1. Locate — simulate the nominal model on the identification recording; estimate the noise level
//     (given, or robustly from the residual's differences); flag windows whose local mean-square error
//     exceeds the noise; find the operating condition (level, rate, time since reversal of u or y) that
//     best characterises them; run Ljung's whiteness and input cross-correlation tests.
//  2. Name — split the identification recording into a fitting part and a held-out tail. Refit the
//     nominal model alone (baseline) and the nominal model with each candidate block (effects.hpp) on
//     the fitting part; score each on the held-out tail by the MSE ratio to the baseline, penalised by
//     for its k extra parameters by the FPE factor (Nf+k)/(Nf-k) of the fitting part and the BIC-like
//     factor exp(k ln Nh / Nh) of the held-out part (so that among equally good blocks the one with
//     fewer parameters wins), and test the per-sample squared-error
//     difference with a batch-means z statistic (robust to coloured residuals). A candidate is
//     significant when z >= significance_z and the penalised MSE reduction >= min_improvement.
//  3. Model and refit — the best significant candidate is refitted on the whole identification
//     recording and must also beat the nominal model on the validation recording (paired z >=
//     validation_z and an MSE reduction >= min_improvement); if it does not, the next significant
//     candidates are tried in rank order (at most max_validated); otherwise the verdict is "none".
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/hw_model.hpp"
#include "diagnose/effects.hpp"
#include "diagnose/refit.hpp"
#include "diagnose/residual_analysis.hpp"

namespace hw::diagnose {

struct Recording {
  std::string name;
  std::vector<double> t, u, y;
};

// A recording from its signals, checked for diagnosis: u, y (and t unless empty: then t is the sample index)
// equally long, t strictly increasing, at least 60 samples. Throws InputError naming `name` and `t_col`.
Recording MakeRecording(std::string name, std::vector<double> t, std::vector<double> u, std::vector<double> y,
                        const std::string& t_col = "t");
// The recording named by a spec (core/recording.hpp: CSV or FILE.mat:u=..,y=..[,t=..]); t_col is optional.
Recording LoadRecording(const std::string& spec, const std::string& u_col, const std::string& y_col,
                        const std::string& t_col);

struct DiagnoseOptions {
  double noise_std = 0.0;             // 0 = estimate from the nominal residual
  std::size_t init_samples = 0;       // leading samples excluded from every cost (transient from rest)
  double holdout_fraction = 1.0 / 3;  // tail of the identification recording used for ranking
  double significance_z = 1.0;        // held-out paired test threshold (a pre-screen; validation decides)
  double min_improvement = 0.05;      // minimum penalised held-out MSE reduction (fraction)
  double validation_z = 2.0;          // the verdict must also beat the nominal on validation
  int max_validated = 3;              // significant candidates tried on validation, in rank order
  int max_lag = 25;                   // lags of the correlation tests
  WindowOptions windows;
  RefitOptions refit;
  std::vector<std::pair<Effect, Location>> candidates;  // empty = CandidateEffects()
  bool IsValid(std::string* error) const;
};

struct Finding {
  EffectBlock block;         // parameters refitted on the fitting part
  int extra_parameters = 0;
  double holdout_mse = 0.0, holdout_mse_nominal = 0.0;
  double mse_ratio = 1.0;    // holdout_mse / holdout_mse_nominal
  double score = 0.0;        // 1 - penalised ratio: fraction of the nominal held-out MSE removed
  double z = 0.0;            // batch-means paired z of the squared-error reduction
  double in_window_share = 0.0;  // share of the error reduction inside the mismatch windows
  bool significant = false;
  std::string evidence;
  nlohmann::json to_json() const;
};

struct FitFigures {
  double rmse = 0.0, fit_percent = 0.0;
  nlohmann::json to_json() const { return {{"rmse", rmse}, {"fit_percent", fit_percent}}; }
};

struct DiagnoseReport {
  bool ok = false;
  std::string message;  // one-paragraph summary for a person
  Effect verdict = Effect::kNone;
  Location verdict_location = Location::kInput;
  std::vector<Finding> findings;  // ranked, best first
  double noise_std = 0.0;
  bool noise_estimated = true;
  std::vector<bool> mask;                                    // identification samples flagged
  std::vector<std::pair<std::size_t, std::size_t>> windows;  // identification sample windows
  std::vector<std::pair<std::size_t, std::size_t>> validation_windows;
  Region region;
  CorrelationTest whiteness_nominal, input_corr_nominal, whiteness_augmented, input_corr_augmented;
  double validation_z = 0.0;
  std::string validation_note;
  bool parameters_off = false;  // refitting the nominal alone already improves validation significantly
  double refit_z = 0.0;         // paired z of that improvement
  FitFigures nominal, nominal_refit, augmented;  // on the validation recording
  FitFigures ident_nominal, ident_augmented;     // on the identification recording
  HwModel nominal_model, nominal_refit_model;
  double nominal_refit_offset = 0.0;  // output offset estimated with the nominal refit
  AugmentedModel augmented_model;  // nominal refit + verdict block (block "none" when no verdict)
  // Signals for plots.
  std::vector<double> ident_nominal_sim, ident_augmented_sim, valid_nominal_sim, valid_augmented_sim;
  std::vector<Condition> conditions;  // on the identification recording
  double seconds = 0.0;
};

// ident and valid must hold equally long t, u, y. Returns report->ok = false with a message when the
// inputs cannot be diagnosed (too short, non-finite simulation).
void Diagnose(const DiagnoseOptions& options, const HwModel& nominal, const Recording& ident, const Recording& valid,
              DiagnoseReport* report);

// report.json content (schema in docs/diagnose.md).
nlohmann::json ReportJson(const DiagnoseReport& r, const Recording& ident, const Recording& valid);
std::string ReportMarkdown(const DiagnoseReport& r, const Recording& ident, const Recording& valid);
// Writes report.json, report.md, models and plot data/scripts into dir; runs gnuplot when available.
// Returns the list of written files.
std::vector<std::string> WriteReport(const DiagnoseReport& r, const Recording& ident, const Recording& valid,
                                     const std::string& dir);

}  // namespace hw::diagnose
