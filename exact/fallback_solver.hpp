#pragma once
// Two LP backends in sequence: the first for every LP, the second for the LPs the first leaves unsolved
// (iteration limit, stall, failure). The interior point (exact/ipm_solver.hpp) is fast on the lifted LPs but
// can stall on an ill-conditioned box where a simplex still finishes; the pair has the speed of the one and
// the reliability of the other. An optimal, cut-off or infeasible answer of the first is final.
#include <memory>

#include "exact/lp_solver.hpp"

namespace hw::exact {

class FallbackSolver : public LpSolver {
 public:
  FallbackSolver(std::string name, std::unique_ptr<LpSolver> first, std::unique_ptr<LpSolver> second);
  std::string name() const override { return name_; }
  LpResult Solve(const LpProblem& problem, const LpBasis& warm, const LpSolveOptions& options) override;

 private:
  std::string name_;
  std::unique_ptr<LpSolver> first_, second_;
};

}  // namespace hw::exact
