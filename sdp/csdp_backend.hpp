#pragma once
// CSDP backend (Borchers), called through the library (libsdp), not through files.
// Our LMI  min c^T y  s.t.  sum y_i F_i - F_0 >= 0  is CSDP's dual problem with C = F_0, A_i = F_i, a = c;
// CSDP's primal objective tr(C X) is our lower bound.
#include "sdp/sdp_solver.hpp"

namespace hw::sdp {

class CsdpSolver : public SdpSolver {
 public:
  std::string name() const override { return "csdp"; }
  SdpSummary Solve(const SdpOptions& options, const LmiProblem& problem) override;
};

}  // namespace hw::sdp
