#pragma once
// The interface every LP backend of the exact-set engine implements (CLP today; exact/clp_solver.hpp).
// A backend solves in floating point and reports what it found; it proves nothing. Proofs come from
// exact/safe_bound.hpp, which turns any dual vector into a rigorous bound.
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "exact/lp_problem.hpp"

namespace hw::exact {

// kCutoff: the solve stopped once its dual bound passed LpSolveOptions::objective_cutoff (the optimum lies above).
enum class LpStatus { kOptimal, kCutoff, kInfeasible, kUnbounded, kIterationLimit, kFailed };
std::string ToString(LpStatus status);

struct LpSolveOptions {
  double primal_tolerance = 1e-9;  // tighter than CLP's default 1e-7: certificates need accurate duals
  double dual_tolerance = 1e-10;
  double time_limit_seconds = 600.0;
  // A backend may stop as soon as it knows the optimum exceeds this (a pruning test needs no more); +inf = solve.
  double objective_cutoff = std::numeric_limits<double>::infinity();
  // The caller's accuracy need: a solve that stops short with its objective within this of its dual bound may
  // report optimal (the dual bound, not the objective, is what gets certified). 0 = the backend's tolerance.
  double acceptable_gap = 0.0;
  bool IsValid(std::string* error) const;
};

struct LpResult {
  LpStatus status = LpStatus::kFailed;
  double objective = 0.0;       // the backend's floating-point value (not a bound)
  std::vector<double> primal;   // column values
  std::vector<double> duals;    // one per row, sign convention of exact/safe_bound.hpp (obj = A' duals + reduced)
  LpBasis basis;                // final basis, to warm-start a related problem
  int iterations = 0;
  bool warm_started = false;
  double seconds = 0.0;
  std::string message;          // the backend's words when not optimal
};

class LpSolver {
 public:
  virtual ~LpSolver() = default;
  virtual std::string name() const = 0;
  // Solves `problem`; `warm` (may be empty or of another shape, then ignored) is the starting basis.
  virtual LpResult Solve(const LpProblem& problem, const LpBasis& warm, const LpSolveOptions& options) = 0;
};

// "clp" (dual simplex, COIN-OR CLP), "glpk" (dual simplex, GNU GLPK), "ipm" (interior point,
// exact/ipm_solver.hpp, with CLP for the LPs it leaves unsolved: exact/fallback_solver.hpp) or "ipm-only" (the
// interior point alone: an LP it leaves unsolved gives its best dual bound, looser, never wrong).
std::unique_ptr<LpSolver> MakeLpSolver(const std::string& name);
std::vector<std::string> AvailableLpSolvers();
bool ValidLpSolverName(const std::string& name, std::string* error);

}  // namespace hw::exact
