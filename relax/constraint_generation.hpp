#pragma once
// Solving a moment relaxation with many candidate inequalities by constraint generation.
//
// Any subset of inequalities gives a relaxation of a LARGER set, so its bound is still valid (a lower
// bound of the min), only possibly looser. If the subset's optimal moments also satisfy every omitted
// localizing constraint (PSD within tolerance), they are feasible for the full relaxation and the bound
// equals the full relaxation's bound. Otherwise the most violated constraints join the working set and
// the relaxation is solved again. Infeasibility of a subset proves infeasibility of the full set.
#include <functional>
#include <string>
#include <vector>

#include "relax/moment_relaxation.hpp"
#include "sdp/verified_bound.hpp"

namespace hw::relax {

struct ConstraintGenerationOptions {
  int order = 0;                    // 0 = minimal
  int max_rounds = 40;
  int add_per_round = 20;           // most violated constraints added per round
  double violation_tolerance = 1e-6;  // min eigenvalue below -tol * max(1, ||L||) counts as violated
  sdp::SdpOptions sdp;
  // Verification of the final round (sdp/verified_bound.hpp): the reported bound becomes the verified one, and
  // an infeasibility certificate that does not verify makes the job fail instead of declaring the set empty.
  sdp::VerifyOptions verify;
  bool IsValid(std::string* error) const;
};

struct ConstraintGenerationResult {
  RelaxationStatus status = RelaxationStatus::kInvalid;
  std::string message;
  double bound = 0.0;        // valid bound of the optimum (lower for min, upper for max) when kSolved
                             // (the verified bound when verification.verified(), else the floating-point one)
  double float_bound = 0.0;  // the solver's floating-point bound (same sign convention)
  sdp::VerifiedBound verification;  // of the final round (lower-bound or infeasibility certificate)
  double primal_value = 0.0;
  bool tight = false;        // true: no omitted constraint is violated, so bound == full relaxation's bound
  double max_violation = 0.0;  // largest relative violation among omitted constraints at the last round
  int rounds = 0;
  std::vector<int> working_set;  // candidate indices used in the last LMI
  std::vector<double> first_moments;
  std::size_t num_moments = 0, num_blocks = 0;
  double solve_seconds = 0.0;  // total SDP time over rounds
  int sdp_iterations = 0;
  sdp::SdpSummary last_sdp;
};

// `core` inequalities are always in the LMI; `candidates` enter on demand, starting from `initial`.
// `on_round` (optional) sees the working set after each round (for resumable runs). When the solver fails on
// a round's LMI (neither optimal nor a certified infeasible/unbounded outcome), `fallback` (optional, e.g. the
// other backend) solves the same LMI before the round is declared failed.
ConstraintGenerationResult SolveWithConstraintGeneration(
    const ConstraintGenerationOptions& options, const PolyProblem& core, const std::vector<Polynomial>& candidates,
    std::vector<int> initial, sdp::SdpSolver& solver,
    const std::function<void(const std::vector<int>&)>& on_round = {}, sdp::SdpSolver* fallback = nullptr);

// A-priori bounds of the LMI variables of a moment relaxation, valid for every feasible point of its LMI.
// When the problem contains a positive multiple of 1 - x_i^2 >= 0 for every variable (or the box [-1, 1]^n),
// every moment up to degree 2 delta satisfies |y_alpha| <= 1 (the localizers give y_{2 gamma} <= y_{2 beta}
// <= ... <= y_0 = 1, and 2x2 minors of the moment matrix bound the rest); an LMI variable that equals a moment
// inherits [-1, 1]. Everything else is unbounded (+-infinity).
sdp::VariableBounds MomentVariableBounds(const PolyProblem& problem, const MomentRelaxation& relaxation);

// LP screen of a semialgebraic set { g_i(x) >= 0 } inside [-1, 1]^n: each monomial of degree <= D becomes a
// free variable with |y_alpha| <= 1 and y_alpha >= 0 for even alpha; infeasibility of this LP proves the set
// empty (every point of the set maps to a feasible y). Returns the SDP summary (one diagonal block).
// With `certificate`, an infeasible outcome is verified rigorously (|y| <= 1 is part of the LP); one that does
// not verify becomes kNumericalTrouble (the set is then not declared empty).
sdp::SdpSummary ScreenWithLinearProgram(const std::vector<Polynomial>& constraints, int num_vars,
                                        const sdp::SdpOptions& options, sdp::SdpSolver& solver,
                                        sdp::VerifiedBound* certificate = nullptr);

// Rigorous bound of min (direction -1) or max (+1) of x_variable over { g_i(x) >= 0 } inside [-1, 1]^n from the
// LP of ScreenWithLinearProgram: the bound is verified from the LP's multiplier (sdp/verified_bound.hpp), so it
// holds whatever the solver's accuracy. Used to contract the prior box before the relaxations (set_membership).
struct LinearProgramBoundResult {
  enum Status { kBounded, kEmpty, kFailed } status = kFailed;  // kEmpty: verified certificate that the set is empty
  double bound = 0.0;  // in [-1, 1], valid when kBounded
  std::string summary_message;
};
LinearProgramBoundResult LinearProgramBound(const std::vector<Polynomial>& constraints, int num_vars, int variable,
                                            int direction, const sdp::SdpOptions& options, sdp::SdpSolver& solver);

}  // namespace hw::relax
