#pragma once
// DSDP 5.8 backend (Benson, Ye; dual scaling), called through the library (libdsdp), not through files.
// DSDP solves  max b^T y  s.t.  C - sum_i A_i y_i >= 0  (its problem (D)); our LMI
// min c^T y  s.t.  sum y_i F_i - F_0 >= 0  is that problem with C = -F_0, A_i = -F_i, b = -c and the same y,
// so DSDP's y is ours and its primal (P)  min C . X, A_i . X = b_i, X >= 0  has our multiplier X
// (F_i . X = c_i, lower bound F_0 . X = -C . X). PSD blocks go to one SDP cone (packed storage), diagonal
// blocks to one LP cone. DSDP takes an initial y (SdpOptions::initial_y).
#include "sdp/sdp_solver.hpp"

namespace hw::sdp {

class DsdpSolver : public SdpSolver {
 public:
  std::string name() const override { return "dsdp"; }
  SdpSummary Solve(const SdpOptions& options, const LmiProblem& problem) override;
};

}  // namespace hw::sdp
