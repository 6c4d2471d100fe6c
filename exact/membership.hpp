#pragma once
// Exact membership of one parameter vector in D (paper 001, eqs. 8-11). For fixed theta the linear block's
// output z_t is affine in its free initial values (z_0 .. z_{T0-1}, T0 = max(na, nb): before T0 the
// recursion would need inputs or outputs before the record), so theta is in D iff an LP in those values has
// a point with p(alpha, L_t) <= z_t <= p(alpha, H_t) for every t (the model-class assumption: p increasing on
// the data range, checked separately). The LP maximises the smallest margin to the band ends.
#include <vector>

#include "exact/lifted_lp.hpp"
#include "exact/lp_solver.hpp"

namespace hw::exact {

struct MembershipResult {
  bool member = false;          // slack >= 0 (and the output map increases on the data range)
  double slack = 0.0;           // the largest smallest band margin, in units of z (negative: outside D)
  bool increasing = false;      // p(alpha, .) increases on the monotonicity grid of the data
  std::vector<double> initial_state;  // z_0 .. z_{T0-1} attaining the slack
};

// theta in the layout's order [gamma_2.., alpha_2.., a_1..a_na, b_j0..b_nb].
MembershipResult CheckMembership(const LiftedData& data, const std::vector<double>& theta, LpSolver& solver);

}  // namespace hw::exact
