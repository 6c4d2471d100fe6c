#pragma once
// The LP over the monomials of a semialgebraic set inside [-1, 1]^n (every monomial a free variable, |y| <= 1,
// even monomials >= 0): its infeasibility proves the set empty (the orthant screen), and its multiplier gives a
// rigorous bound of one variable.
#include <string>
#include <vector>

#include "core/polynomial.hpp"
#include "sdp/sdp_solver.hpp"
#include "sdp/verified_bound.hpp"

namespace hw::pop {

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

}  // namespace hw::pop
