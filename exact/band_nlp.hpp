#pragma once
// The extreme-parameter problem of D as a smooth NLP for Ipopt: variables (theta, z_0 .. z_{T0-1}); the linear
// block's output z_t is simulated from them, and every band p(alpha, L_t) + margin <= z_t <= p(alpha, H_t) -
// margin and the monotonicity rows p(alpha, g_{m+1}) >= p(alpha, g_m) are constraints. The Jacobian and the
// Hessian are exact (first- and second-order forward sensitivities of the recursion, dense: the problem has few
// variables; a limited-memory Hessian stalled for hundreds of iterations near each optimum). Used by
// ComputeInnerHull, which re-checks every point it returns.
#include <string>
#include <vector>

#include "exact/lifted_lp.hpp"

namespace hw::exact {

struct BandNlpRequest {
  int parameter = 0;                 // the layout index to push
  int direction = 1;                 // +1: maximise it, -1: minimise it
  std::vector<double> theta;         // start
  std::vector<double> initial_state; // start, z_0 .. z_{T0-1}
  double margin = 0.0;               // kept from each band end, in units of z
  double cpu_seconds = 60.0;         // the limit for this request (Ipopt's CPU time, the working set's rounds)
};

struct BandNlpResult {
  bool returned = false;       // Ipopt returned a point (whatever its status)
  std::vector<double> theta;   // in the box
  std::vector<double> initial_state;
  std::string status;          // Ipopt's return status (of the last round), for messages
  int rounds = 0;              // Ipopt solves: the working set grew rounds - 1 times
  int working_samples = 0;     // samples whose bands were constraints in the last round
};

BandNlpResult SolveBandNlp(const LiftedData& data, const ParamBox& box, const BandNlpRequest& request);

}  // namespace hw::exact
