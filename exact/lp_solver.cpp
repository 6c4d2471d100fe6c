#include "exact/lp_solver.hpp"
#include <algorithm>
#include <cmath>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "exact/clp_solver.hpp"
#include "exact/fallback_solver.hpp"
#include "exact/glpk_solver.hpp"
#include "exact/ipm_solver.hpp"

namespace hw::exact {

std::string ToString(LpStatus status) {
  switch (status) {
    case LpStatus::kOptimal: return "optimal";
    case LpStatus::kCutoff: return "cutoff";
    case LpStatus::kInfeasible: return "infeasible";
    case LpStatus::kUnbounded: return "unbounded";
    case LpStatus::kIterationLimit: return "iteration limit";
    case LpStatus::kFailed: return "failed";
  }
  return "failed";
}

bool LpSolveOptions::IsValid(std::string* error) const {
  if (!(primal_tolerance > 0 && primal_tolerance < 1e-3) || !(dual_tolerance > 0 && dual_tolerance < 1e-3)) {
    if (error) *error = "LP tolerances must lie in (0, 1e-3)";
    return false;
  }
  if (!(acceptable_gap >= 0.0)) {
    if (error) *error = "the LP's acceptable gap must be >= 0";
    return false;
  }
  if (std::isnan(objective_cutoff)) {
    if (error) *error = "the LP objective cutoff must be a number (+inf: none)";
    return false;
  }
  if (!(time_limit_seconds > 0)) {
    if (error) *error = "the LP time limit must be positive";
    return false;
  }
  return true;
}

std::vector<std::string> AvailableLpSolvers() { return {"clp", "glpk", "ipm", "ipm-only"}; }

bool ValidLpSolverName(const std::string& name, std::string* error) {
  const auto names = AvailableLpSolvers();
  if (std::find(names.begin(), names.end(), name) != names.end()) return true;
  if (error) *error = fmt::format("LP solver '{}' unknown; expected one of: {}", name, fmt::join(names, ", "));
  return false;
}

std::unique_ptr<LpSolver> MakeLpSolver(const std::string& name) {
  std::string error;
  if (!ValidLpSolverName(name, &error)) throw std::invalid_argument(error);
  if (name == "glpk") return std::make_unique<GlpkSolver>();
  if (name == "ipm-only") return std::make_unique<IpmSolver>();
  if (name == "ipm")
    return std::make_unique<FallbackSolver>("ipm", std::make_unique<IpmSolver>(), std::make_unique<ClpSolver>());
  return std::make_unique<ClpSolver>();
}

}  // namespace hw::exact
