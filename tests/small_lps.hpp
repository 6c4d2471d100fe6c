#pragma once
// Small LPs with known optima, shared by the LP backend tests.
#include <cmath>

#include "exact/lp_problem.hpp"

namespace hw::exact::testing_lps {

// min x + y  s.t.  x + 2y >= 2, 3x + y >= 3, 0 <= x, y <= 10: optimum 1.4 at (x, y) = (0.8, 0.6), columns 0, 1.
inline LpProblem TwoRowLp() {
  LpProblem lp;
  const int x = lp.AddColumn(0, 10), y = lp.AddColumn(0, 10);
  lp.obj = {1.0, 1.0};
  const int r1 = lp.AddRow(2, INFINITY), r2 = lp.AddRow(3, INFINITY);
  lp.AddEntry(r1, x, 1), lp.AddEntry(r1, y, 2), lp.AddEntry(r2, x, 3), lp.AddEntry(r2, y, 1);
  return lp;
}

}  // namespace hw::exact::testing_lps
