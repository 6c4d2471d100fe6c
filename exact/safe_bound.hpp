#pragma once
// Rigorous bounds of an LP from any dual vector (Neumaier and Shcherbina, "Safe bounds in linear and
// mixed-integer programming", Math. Program. 2004). For every x with row_lo <= A x <= row_hi and
// col_lo <= x <= col_hi (the exact coefficients: each stored one is the midpoint of an interval),
//   obj' x = y' A x + (obj - A' y)' x  >=  sum_i y_i (row_lo_i or row_hi_i)  +  sum_j min (obj - A' y)_j x_j,
// evaluated in outward-rounded interval arithmetic. The duals only steer the bound; a poor dual vector gives a
// weak bound, never a wrong one. A dual of the wrong sign for an infinite row bound is set to zero.
#include <vector>

#include "exact/lp_problem.hpp"

namespace hw::exact {

// A rigorous lower bound of min obj' x over the exact problem's feasible set (+inf proves it empty only in
// the limit; callers compare the bound with a threshold). `objective` overrides problem.obj when non-empty.
double SafeLowerBound(const LpProblem& problem, const std::vector<double>& duals,
                      const std::vector<double>& objective = {});

}  // namespace hw::exact
