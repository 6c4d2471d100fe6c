#pragma once
// Stage 1 of Brouri's method (paper 000, Section 4): the nonlinearities from piecewise-constant inputs.
//
// Experiment (the consistent reading used here; the paper's eq. 13 indices are garbled):
//   a reset hold at U_0, then ascending holds U_1 < ... < U_N, then descending holds
//   U_{N+1} > ... > U_{2N'} (the descending list need not mirror the ascending one: the paper's own
//   Table 1 does not). The reset hold puts the working point on the descending border so that each
//   ascending level is reached by an increase; the paper's plateau (eq. 7a, V_j = F[U_1]) is then
//   "same output as the reset hold", and for the descending stage "same output as the last ascending hold".
// In steady state the system is the static map h o F (eq. 5); eq. 9 averages the last M samples of each
// hold. j_a, j_d (length of the plateaus) are detected from the data with a significance test: a hold is
// on the plateau while the mean of its whole hold equals the pooled reference (reset hold's tail and the
// plateau holds found so far) within plateau_sigmas standard errors.
// With the normalised model (eq. 4: S^a = 1, G(0) = 1):
//   ascending border points:  X_j = h(U_j - d+)            -> degree-p fit q_a, d+ = its root (h(0) = 0)
//   h(u) = q_a(u + d+)                                      (eq. 12)
//   descending border points: X_j = h(S^d (U_j - d-))      -> degree-p fit q_d
//   The decomposition q_d = h o (S^d (u - d-)) gives S^d and d- in three ways (all are reported):
//    kPaperCoefficients: S^d = (lead(q_d) / lead(h))^(1/p), d- from the u^(p-1) coefficient (the paper's
//      "leading coefficient" and "any other coefficient");
//    kLeadingAndRoot: the same S^d, d- = the root of q_d (h(0) = 0, as for d+);
//    kRootAndSlope: d- = the root of q_d, S^d = q_d'(d-) / h^'(0) (slopes at the zero crossing).
//   Default kLeadingAndRoot: on the paper's example (100 noise seeds, docs/brouri.md) the root gives d-
//   with std 0.002 against 0.013 from the u^4 coefficient; the leading coefficient gives S^d with std
//   0.014 against 0.019 from the slopes. (A least-squares fit of X_j = h^(S (U_j - d)) was tried and is
//   worse still: it evaluates h^ far outside the range the ascending points cover.)
// A backlash-inverse input (eq. 2) has no plateau (j_a = j_d = 0) and its "up" line lies LEFT of its
// "down" line; the estimator reads the operator kind from that order, it is not told.
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "estimators/brouri/system.hpp"

namespace hw::brouri {

// Eq. 9 on one hold: mean of its last `average_samples` samples, and the standard error of that mean; isolated
// outliers are left out and listed.
struct HoldAverage {
  double level = 0.0;   // U_j
  double mean = 0.0;    // X^_j(M)
  double std_error = 0.0;
  int samples = 0;
  // Over the WHOLE hold: on a plateau v does not move, so y is flat from the hold's first sample and
  // all of it can be compared with the reference; this gives the plateau test far more samples than M.
  double hold_mean = 0.0, hold_std_error = 0.0;
  // Isolated outliers (estimators/brouri/outliers.hpp) left out of both averages: 0-based sample indices of
  // the recording, ascending; and the median of the settled part they were judged against.
  std::vector<std::size_t> outliers;
  double median = 0.0;
};
// Holds are consecutive blocks of `hold_samples` samples of y starting at sample 0.
std::vector<HoldAverage> AverageHolds(const std::vector<double>& y, const std::vector<double>& levels,
                                      int hold_samples, int average_samples);

enum class DownBorderMethod { kPaperCoefficients, kLeadingAndRoot, kRootAndSlope };
const char* ToString(DownBorderMethod method);
DownBorderMethod DownBorderMethodFromString(const std::string& name);  // throws InputError

struct NonlinearOptions {
  int degree = 0;              // p; 0 selects it from the data (smallest degree the residuals accept)
  int max_degree = 9;          // upper limit of the selection
  double plateau_sigmas = 5.0; // a hold belongs to the plateau if within this many standard errors
  double plateau_abs_tol = 0.0;// plus this absolute tolerance (noise-free data: leave 0)
  DownBorderMethod down_border = DownBorderMethod::kLeadingAndRoot;
  // Not in the paper: after its estimates, refit h, d+, S^d, d- jointly to BOTH borders' points
  // (X_j = h(U_j - d+) ascending, h(S^d (U_j - d-)) descending; h(0) = 0; Levenberg-Marquardt on the
  // three border parameters, h by linear least squares). Uses all points for h, so h^ is no longer
  // extrapolated over the descending range. Needs at least p + 3 border points in all.
  bool joint_refit = false;
  bool IsValid(std::string* error) const;
};

struct NonlinearEstimate {
  OperatorKind kind = OperatorKind::kBacklash;  // detected from the line order
  int degree = 0;                                // p used
  int j_a = 0, j_d = 0;                          // plateau lengths
  HoldAverage reset;
  std::vector<HoldAverage> up, down;             // averaged holds, paper's X^_j(M)
  std::vector<double> q_up, q_down;              // fits of h(u - d+) and h(S^d (u - d-)), ascending coeffs
  std::vector<double> h;                         // h^ (normalised model), ascending coeffs, h[0] = 0
  OperatorLines lines;                           // normalised: slope_up = 1
  // The three readings of the descending border (see DownBorderMethod): {S^d, d-} each.
  double s_down_leading = 0.0, d_down_coefficient = 0.0, d_down_root = 0.0, s_down_slope = 0.0;
  BacklashParams params;                         // of the detected kind, normalised (S^a = 1)
  bool joint_refit = false;                      // params and h come from the joint refit
  OperatorLines paper_lines;                     // the paper's two-step lines (before any refit)
  std::string warnings;

  nlohmann::json to_json() const;
  // Throws InputError, also for an unknown key; `extension_keys` are keys of an enclosing record the caller
  // reads itself (the stage-1 result file adds "stage" and "summary").
  static NonlinearEstimate from_json(const nlohmann::json& j, const std::vector<std::string_view>& extension_keys = {});
  // The pre-compensator of Fig. 8 that cancels the estimated operator (see the .cpp for the
  // backlash-inverse plant, where the paper's Lemma 1 overstates what a backlash can do).
  MemoryOperator Precompensator() const;
};

struct Summary {
  bool ok = false;
  std::string message;
};

void EstimateNonlinearities(const NonlinearOptions& options, const HoldAverage& reset,
                            const std::vector<HoldAverage>& up, const std::vector<HoldAverage>& down,
                            NonlinearEstimate* estimate, Summary* summary);

}  // namespace hw::brouri
