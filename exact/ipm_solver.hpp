#pragma once
// A primal-dual interior-point method (Mehrotra predictor-corrector) behind exact/lp_solver.hpp.
//
// Why a third backend: the lifted LPs are banded in t apart from a few parameter columns. A simplex pivots
// through thousands of bases whose cost grows faster than N; an interior-point method solves a few dozen
// linear systems whose sparse LDL' (the quasi-definite augmented system, AMD ordering puts the dense
// parameter columns last) costs time linear in N. It keeps no basis, so it never warm-starts. Its duals are
// as good as any other for the certificate: exact/safe_bound.hpp turns any dual vector into a rigorous bound,
// and the bound is only as loose as the solve is inaccurate.
#include "exact/lp_solver.hpp"

namespace hw::exact {

class IpmSolver : public LpSolver {
 public:
  std::string name() const override { return "ipm-only"; }
  // `warm` is ignored (no basis). Stops when optimal to the options' tolerances, or, with an objective cutoff,
  // as soon as its dual bound exceeds the cutoff (status kCutoff).
  LpResult Solve(const LpProblem& problem, const LpBasis& warm, const LpSolveOptions& options) override;
};

}  // namespace hw::exact
