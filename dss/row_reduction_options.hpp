#pragma once
// Options of the exact row reduction (dss/row_reduction.hpp), apart so that BoundsOptions can hold them.
#include <string>

namespace hw::dss {

struct RowReductionOptions {
  bool enabled = true;
  // A combination counts when max_alpha |g_i - sum lambda_j g_j - ...|_alpha <= residual_tolerance (rows are
  // normalised to max |coefficient| = 1).
  double residual_tolerance = 1e-9;
  // Simplex iterations allowed for one row's LP (from the warm basis, and again from the standard basis). These
  // LPs are highly degenerate (zero objective) and GLPK's primal simplex can cycle on them: on a 300-sample
  // record of the paper's example one LP ran millions of iterations without end, where the others need at most
  // about 80. A row whose LP hits the limit twice is kept, which is always valid (keeping a row never loosens a
  // relaxation), and iteration counts, unlike time limits, keep the result independent of the machine.
  int simplex_iteration_limit = 5000;
  bool IsValid(std::string* error) const;
};

}  // namespace hw::dss
