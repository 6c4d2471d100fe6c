#pragma once
// Discrepancy diagnosis: where does a nominal model's simulation differ from a recording, which
// physical effect did it leave out, and does inserting that effect improve held-out data?
//
// Procedure (Diagnose):
//  1. Baseline — the nominal model refitted alone on the fitting part (first 2/3) of the
//     identification recording, from the given numbers and, when the structure is known, from several
//     fresh starts (nominal_fit.hpp); the best by held-out error is the baseline every candidate must
//     beat. A bad nominal fit is therefore never blamed on an effect: the nominal refit is itself a
//     candidate and is reported as such. Richer structures (orders + 1, map degrees + 2) are fitted too:
//     every effect must beat them on the held-out tail, and one that beats the baseline on both parts
//     must be beaten on validation as well; only when no effect does it becomes the baseline (the effects
//     are then sought again on top of it).
//  2. Search — every candidate block (effects.hpp) is added to the baseline and refitted on the
//     fitting part (in parallel), scored on the held-out tail, refitted on the whole identification
//     recording and scored on the validation recording. Scores are MSE ratios to the baseline,
//     penalised for the k extra parameters (FPE factor (Nf+k)/(Nf-k) on the fitting part, BIC-like
//     factor exp(k ln N / N) on each scored part); significance is a batch-means paired z of the
//     per-sample squared-error reduction (robust to coloured residuals). A candidate is eligible when
//     it is significant on the held-out tail (z >= significance_z, penalised reduction >=
//     min_improvement) and on validation (z >= validation_z, reduction >= min_improvement); when only
//     validation is, the first test is repeated with the recordings' roles swapped (refit on validation,
//     scored on identification, as strict as validation; the blocks must matter in that refit and the
//     whole-recording refit must lower the identification error) and stands in for the held-out one; the
//     verdict is the eligible candidate with the best combined (geometric-mean) penalised score. When only
//     one of the two tests confirms a candidate, the other fit is restarted from the confirmed one (and,
//     on the whole recording, from the block's grid) and kept when its own training cost drops.
//  3. Combination — when a verdict exists, pairs of it with the next candidates are tried and kept
//     only if the pair beats the single block by the same two tests.
//  4. Locate — the mismatch windows are the samples where the verdict's blocks change the
//     prediction by more than the noise (model with vs. without the blocks); without a verdict, the
//     samples where the residual's local mean square exceeds the noise (family-wise threshold).
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/hw_model.hpp"
#include "diagnose/effects.hpp"
#include "diagnose/locate.hpp"
#include "diagnose/nominal_fit.hpp"
#include "diagnose/recording.hpp"
#include "diagnose/refit.hpp"
#include "diagnose/residual_analysis.hpp"

namespace hw::diagnose {

// What the baseline (the nominal refitted alone) reaches on the held-out tail against the noise.
enum class NominalStatus {
  kReachedNoiseFloor,  // held-out RMSE <= noise_floor_factor x noise
  kExplainedByEffect,  // above it, and the verdict explains at least half of the excess mean square
  kFailed,             // above it and nothing explains it: no effect verdict is given
};
std::string NominalStatusName(NominalStatus s);  // "reached_noise_floor", "explained_by_effect", "failed"

// Recordings made around an operating point far from 0 are diagnosed in deviations u - u_op, y - y_op
// (u_op, y_op = the identification recording's means, as in the usual detrending: the median of a
// two-level or step input is one of its levels, which would put the 0 of a relay or a state effect at
// the edge of the signal), so that effects acting around the operating point (a dead band, a relay) are
// found there and polynomial maps stay well conditioned.
struct OperatingPoint {
  bool u_removed = false, y_removed = false;
  double u = 0.0, y = 0.0;
  // Far from 0: the signal stays on one side of 0 (1 % and 99 % quantiles) and its median is more than
  // twice its 1-99 % spread away from 0 (a tank level between 1 and 10 V is not: its 0 is physical).
  static OperatingPoint Of(const Recording& ident);
  Recording Centred(const Recording& r) const;
  nlohmann::json to_json() const;
};

// Feedback: does the input depend on past output residuals? A Granger test: u_t regressed on its own
// past (lags 1..L) with and without the residual's past (lags 1..L), the 10 % largest innovations of u
// left out; the F statistic x L is compared with the chi^2_L quantile at 1 - 1e-5. In closed loop the
// noise reaches the input; the diagnosis still simulates from the recorded input (output error stays
// consistent with white noise), and says so.
struct FeedbackTest {
  bool detected = false;
  double statistic = 0.0, threshold = 0.0;
  int lags = 0;
  nlohmann::json to_json() const;
};
FeedbackTest DetectFeedback(const std::vector<double>& u, const std::vector<double>& e, std::size_t skip, int lags);

struct DiagnoseOptions {
  double noise_std = 0.0;             // 0 = estimate from the residuals
  std::size_t init_samples = 0;       // leading samples excluded from every cost (warm-up)
  double holdout_fraction = 1.0 / 3;  // tail of the identification recording used for ranking
  double significance_z = 1.0;        // held-out paired test threshold
  double min_improvement = 0.05;      // minimum penalised MSE reduction (fraction), held-out and validation
  double validation_z = 2.0;          // validation paired test threshold
  // Penalised reduction a candidate needs on validation and with the recordings' roles swapped when the
  // held-out tail does not confirm it; 1 = off. The swapped test also asks that the blocks themselves
  // matter in the model refitted on validation (removed, it is significantly worse on identification)
  // and that the candidate refitted on the whole identification recording lowers its error there:
  // without these two, 0.3 named an effect on 1 of 60 null recordings with a fitted nominal (a better
  // optimum of a cubic input map under a two-level input, extrapolated to validation's levels).
  double swapped_min_improvement = 0.3;
  bool try_pairs = true;              // combinations of two blocks when one leaves a significant misfit
  int pair_partners = 3;              // candidates tried as the second block
  int max_lag = 25;                   // lags of the correlation tests
  int threads = 0;                    // candidate fits in parallel; 0 = hardware concurrency
  StateVariable state_variable = StateVariable::kPosition;  // what the linear block's output is
  WindowOptions windows;
  RefitOptions refit;
  NominalFitOptions nominal_fit;      // fresh starts of the baseline (when the structure is known)
  std::vector<std::pair<Effect, Location>> candidates;  // empty = CandidateEffects()
  bool remove_operating_point = true;  // diagnose in deviations when the recording is far from 0
  bool richer_nominal = true;          // an effect must also beat a richer nominal (orders + 1, map degrees + 2)
  double noise_floor_factor = 1.2;     // the baseline reached the noise when its held-out RMSE <= this x noise
  int feedback_lags = 10;
  bool IsValid(std::string* error) const;
};

// One side (held-out tail or validation recording) of a candidate's comparison with the baseline.
struct Comparison {
  double mse = 0.0, mse_baseline = 0.0;
  double ratio = 1.0;  // mse / mse_baseline
  double score = 0.0;  // 1 - penalised ratio
  double z = 0.0;      // batch-means paired z of the squared-error reduction
  bool significant = false;
  nlohmann::json to_json() const;
};

struct Finding {
  AugmentedModel fitted;     // fitted on the fitting part of the identification recording
  AugmentedModel model;      // refitted on the whole identification recording (blocks + nominal)
  std::vector<EffectBlock> blocks;  // the candidate's blocks, as fitted on the fitting part
  int extra_parameters = 0;
  Comparison holdout, validation;
  Comparison swapped;          // roles swapped (refit on validation, scored on identification), see Diagnose
  bool swapped_tested = false; // tried when validation confirms a candidate the held-out tail does not
  bool swapped_stands_in = false;  // the swapped test passed (with its guards) and replaced the held-out one
  double score = 0.0;        // combined: 1 - sqrt(penalised ratio held-out x penalised ratio validation)
  bool eligible = false;     // significant on both (held-out or swapped), better than the richer nominal, meaningful
  bool beats_richer = true;  // held-out score above the richer nominal's
  bool meaningful = true;    // parameters describe a physical device (no dead band covering the signal)
  bool jumpless_stiction = false;  // stiction with equal bands, not named over an eligible backlash
  double in_window_share = 0.0;  // share of the held-out error reduction inside the residual windows
  std::string evidence;
  std::string Label() const;
  nlohmann::json to_json() const;
};

struct FitFigures {
  double rmse = 0.0, fit_percent = 0.0;
  nlohmann::json to_json() const { return {{"rmse", rmse}, {"fit_percent", fit_percent}}; }
};

struct DiagnoseReport {
  bool ok = false;
  std::string message;  // one-paragraph summary for a person
  Effect verdict = Effect::kNone;  // primary block of the verdict
  Location verdict_location = Location::kInput;
  std::vector<EffectBlock> verdict_blocks;  // one, or two for a combination
  std::vector<Finding> findings;            // single blocks, ranked best first
  std::vector<Finding> pairs;               // combinations tried, ranked
  // Baseline: the nominal model refitted alone.
  std::string baseline_source;              // which start the baseline came from
  std::vector<NominalStart> baseline_starts;
  double noise_std = 0.0;
  bool noise_estimated = true;
  NominalStatus nominal_status = NominalStatus::kReachedNoiseFloor;
  double baseline_holdout_rmse = 0.0;  // of the baseline, on the held-out tail
  std::string nominal_status_note;
  std::string richer_note;             // the richer nominal every effect had to beat, and its score
  OperatingPoint operating_point;
  FeedbackTest feedback;               // on the identification recording, from the best model's residual
  // Locate: where the verdict's blocks change the prediction (identification recording), or, without
  // a verdict, where the nominal residual exceeds the noise.
  std::string mask_source;
  std::vector<bool> mask;
  std::vector<std::pair<std::size_t, std::size_t>> windows;
  std::vector<std::pair<std::size_t, std::size_t>> validation_windows;
  std::vector<bool> residual_mask;          // nominal residual beyond the noise (for the figures)
  std::vector<BlockWindows> block_windows;  // where each verdict block (each limit) acts on its own
  Region region;
  CorrelationTest whiteness_nominal, input_corr_nominal, whiteness_augmented, input_corr_augmented;
  double validation_z = 0.0;
  std::string validation_note;
  bool parameters_off = false;  // refitting the nominal alone already improves validation significantly
  double refit_z = 0.0;         // paired z of that improvement
  FitFigures nominal, nominal_refit, augmented;  // on the validation recording
  FitFigures ident_nominal, ident_augmented;     // on the identification recording
  AugmentedModel nominal_model, nominal_refit_model, augmented_model;
  std::string initial_state_note;  // what the estimated initial state does to the first samples
  // Signals for plots.
  std::vector<double> ident_nominal_sim, ident_augmented_sim, valid_nominal_sim, valid_augmented_sim;
  std::vector<Condition> conditions;  // on the identification recording
  double seconds = 0.0;
};

// Exactly one nominal model is given: a Model JSON (CLI --model, Python model) or a spec to fit it (--fit, fit).
// False with the message the CLI and the Python module share in *error otherwise.
bool ValidNominalChoice(bool has_model, bool has_fit, std::string* error);

// ident and valid must hold equally long t, u, y. `nominal` must have no effect blocks. When
// `structure` is given (the nominal's structure, e.g. from --fit), the baseline is also refitted from
// fresh starts. Returns report->ok = false with a message when the inputs cannot be diagnosed.
void Diagnose(const DiagnoseOptions& options, const AugmentedModel& nominal, const NominalSpec* structure,
              const Recording& ident, const Recording& valid, DiagnoseReport* report);

// Fits `spec` as Diagnose sees the recording (operating point removed when options say so), e.g. for --fit.
NominalFit FitNominalForDiagnosis(const NominalSpec& spec, const Recording& ident, const DiagnoseOptions& options);

// report.json content (schema in docs/diagnose.md).
nlohmann::json ReportJson(const DiagnoseReport& r, const Recording& ident, const Recording& valid);
std::string ReportMarkdown(const DiagnoseReport& r, const Recording& ident, const Recording& valid);
// Writes report.json, report.md, models and plot data/scripts into dir; runs gnuplot when available.
// Returns the list of written files.
std::vector<std::string> WriteReport(const DiagnoseReport& r, const Recording& ident, const Recording& valid,
                                     const std::string& dir);

}  // namespace hw::diagnose
