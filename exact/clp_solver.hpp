#pragma once
// COIN-OR CLP behind exact/lp_solver.hpp: dual simplex, warm-started from a given basis.
#include "exact/lp_solver.hpp"

namespace hw::exact {

class ClpSolver : public LpSolver {
 public:
  std::string name() const override { return "clp"; }
  LpResult Solve(const LpProblem& problem, const LpBasis& warm, const LpSolveOptions& options) override;
};

}  // namespace hw::exact
