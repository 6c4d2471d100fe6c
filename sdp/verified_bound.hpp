#pragma once
// Rigorous (verified) bounds from an approximate SDP multiplier, in the manner of Jansson, Chaykin and
// Keil's VSDP. For the LMI problem  min c^T y + offset  s.t.  F(y) = sum_i y_i F_i - F_0 >= 0  and ANY
// symmetric block matrix X (e.g. a solver's approximate multiplier), every feasible y satisfies
//
//     c^T y = F(y) . X + F_0 . X + r^T y,             r_i = c_i - F_i . X,
//           >= F_0 . X + sum_j min(0, lambda_min(X_j)) * T_j + sum_i min(r_i lo_i, r_i hi_i),
//
// where lo <= y <= hi and tr F_j(y) <= T_j hold for every feasible y (a-priori bounds; T_j follows from the
// box). Every quantity is enclosed with interval arithmetic (CGAL::Interval_nt, directed rounding), and
// lambda_min(X_j) is bounded below around a floating-point eigen-decomposition X ~ V D V^T by Weyl's
// theorem: lambda_min(X) >= d_min * (1 -/+ ||V^T V - I||) - ||X - V D V^T||_F, the norms enclosed from above.
//
// Infeasibility: with c = 0 the same bound reads 0 >= bound for every feasible y, so a verified bound > 0
// proves that the LMI (intersected with the a-priori box) has no solution.
#include <ostream>
#include <string>
#include <vector>

#include <Eigen/Dense>
#include <nlohmann/json.hpp>

#include "sdp/lmi_problem.hpp"
#include "sdp/sdp_solver.hpp"

namespace hw::sdp {

// lower[i] <= y_i <= upper[i] for EVERY feasible y of the LMI (derived from the LMI itself, e.g. moment bounds
// in scaled coordinates); +-infinity where nothing is known.
struct VariableBounds {
  std::vector<double> lower, upper;
  static VariableBounds Uniform(int m, double lo, double hi) {
    return {std::vector<double>(m, lo), std::vector<double>(m, hi)};
  }
};

struct VerifyOptions {
  bool enabled = true;
  // A verified bound looser than the floating-point bound by more than this (relative to max(1, |bound|)) is
  // repaired: first X is projected onto the equalities (cheap); then, when the bound is still unverified or
  // the eigenvalue term dominates, perturbed re-solves (X >= eps I, VSDP's remedy for multipliers that are
  // not safely PSD). A re-solve costs a full SDP solve.
  double acceptable_correction = 1e-7;
  int max_resolves = 2;
  double perturbation = 1e-8;  // eps of the first re-solve, relative to max(1, max |X_ij|); x10 per retry
  bool IsValid(std::string* error) const;
};

enum class VerifyStatus { kNotRun, kVerified, kUnverified };
std::string ToString(VerifyStatus s);  // "off", "verified", "unverified"
// JSON holds the name (nlohmann::json finds this by argument-dependent lookup).
inline void to_json(nlohmann::json& j, VerifyStatus s) { j = ToString(s); }
inline std::ostream& operator<<(std::ostream& os, VerifyStatus s) { return os << ToString(s); }

struct VerifiedBound {
  VerifyStatus status = VerifyStatus::kNotRun;
  std::string message;
  // Lower bound: a rigorous lower bound of min c^T y + offset (kVerified), -infinity when none could be made.
  // Infeasibility: the rigorous lower bound of 0 over the feasible set (kVerified iff > 0).
  double bound = 0.0;
  double float_bound = 0.0;   // the floating-point value it corrects (solver's F_0 . X + offset)
  double correction = 0.0;    // float_bound - bound (>= 0 unless the solver's value was pessimistic)
  double residual_term = 0.0;    // rigorous lower bound of sum_i r_i y_i
  double eigenvalue_term = 0.0;  // rigorous lower bound of sum_j min(0, lambda_min(X_j)) T_j
  double min_eigenvalue = 0.0;   // rigorous lower bound of min_j lambda_min(X_j)
  int resolves = 0;              // perturbed re-solves used
  double seconds = 0.0;          // verification time (re-solves included)
  double resolve_seconds = 0.0;  // of which re-solves
  bool verified() const { return status == VerifyStatus::kVerified; }
  nlohmann::json to_json() const;
};

// Rigorous lower bound of lambda_min of the symmetric matrix taken from the upper triangle of A
// (-infinity when A is not finite or the eigen-decomposition is unusable).
double MinEigenvalueLowerBound(const Eigen::MatrixXd& A);

// Verified lower bound of min c^T y + offset over {F(y) >= 0, bounds}, from the multiplier X (block by block;
// only upper triangles are read, diagonal blocks only on the diagonal). float_bound is what it corrects.
VerifiedBound VerifyLowerBound(const LmiProblem& problem, const std::vector<Eigen::MatrixXd>& X,
                               const VariableBounds& bounds, double float_bound);

// Verifies that X certifies infeasibility of {F(y) >= 0, bounds}: status kVerified iff the rigorous bound > 0.
VerifiedBound VerifyInfeasibility(const LmiProblem& problem, const std::vector<Eigen::MatrixXd>& X,
                                  const VariableBounds& bounds);

// Verifies ANY multiplier (an optimal solve's, or the last iterate of a solve that stopped short: weak duality
// needs no convergence), and when the correction exceeds acceptable_correction (relative to max(1, |float|))
// also X projected onto the equalities; keeps the better. No re-solve.
VerifiedBound VerifyMultiplier(const LmiProblem& problem, const std::vector<Eigen::MatrixXd>& X,
                               const VariableBounds& bounds, double float_bound, double acceptable_correction);

// Verifies an optimal solve; when the correction exceeds options.acceptable_correction, verifies X projected
// onto the equalities F_i . X = c_i too; when still unverified (or the eigenvalue term dominates), solves
// the perturbed problem min (c - eps tr F)^T y (whose multiplier X' gives X = X' + eps I >= eps I with the
// same equalities) up to max_resolves times. Keeps the best verified bound. `summary` must be optimal and
// hold X.
VerifiedBound VerifyOptimalSolve(const VerifyOptions& options, const SdpOptions& sdp_options, const LmiProblem& problem,
                                 const VariableBounds& bounds, const SdpSummary& summary, SdpSolver& solver);

}  // namespace hw::sdp
