#pragma once
// GNU GLPK behind exact/lp_solver.hpp: dual simplex (primal when the dual phase fails), warm-started from a
// given basis. A second backend, so measurements can choose (benchmarks/exact_lp_bench.cpp).
#include "exact/lp_solver.hpp"

namespace hw::exact {

class GlpkSolver : public LpSolver {
 public:
  std::string name() const override { return "glpk"; }
  LpResult Solve(const LpProblem& problem, const LpBasis& warm, const LpSolveOptions& options) override;
};

}  // namespace hw::exact
