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

namespace hw::relax {

struct ConstraintGenerationOptions {
  int order = 0;                    // 0 = minimal
  int max_rounds = 40;
  int add_per_round = 20;           // most violated constraints added per round
  double violation_tolerance = 1e-6;  // min eigenvalue below -tol * max(1, ||L||) counts as violated
  sdp::SdpOptions sdp;
  bool IsValid(std::string* error) const;
};

struct ConstraintGenerationResult {
  RelaxationStatus status = RelaxationStatus::kInvalid;
  std::string message;
  double bound = 0.0;        // valid bound of the optimum (lower for min, upper for max) when kSolved
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

// LP screen of a semialgebraic set { g_i(x) >= 0 } inside [-1, 1]^n: each monomial of degree <= D becomes a
// free variable with |y_alpha| <= 1 and y_alpha >= 0 for even alpha; infeasibility of this LP proves the set
// empty (every point of the set maps to a feasible y). Returns the SDP summary (one diagonal block).
sdp::SdpSummary ScreenWithLinearProgram(const std::vector<Polynomial>& constraints, int num_vars,
                                        const sdp::SdpOptions& options, sdp::SdpSolver& solver);

}  // namespace hw::relax
