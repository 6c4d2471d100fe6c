#pragma once
// SDPA 7 backend, called through the C++ class SDPA (libsdpa), not through files.
// Our LMI is exactly SDPA's primal form:  min sum c_i x_i  s.t.  X = sum F_i x_i - F_0 >= 0;
// SDPA's dual objective F_0 . Y is our lower bound.
#include "sdp/sdp_solver.hpp"

namespace hw::sdp {

class SdpaSolver : public SdpSolver {
 public:
  std::string name() const override { return "sdpa"; }
  SdpSummary Solve(const SdpOptions& options, const LmiProblem& problem) override;
};

}  // namespace hw::sdp
