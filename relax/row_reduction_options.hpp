#pragma once
// Options of the exact row reduction (relax/row_reduction.hpp), apart so that BoundsOptions can hold them.
#include <string>

namespace hw::relax {

struct RowReductionOptions {
  bool enabled = true;
  // A combination counts when max_alpha |g_i - sum lambda_j g_j - ...|_alpha <= residual_tolerance (rows are
  // normalised to max |coefficient| = 1).
  double residual_tolerance = 1e-9;
  bool IsValid(std::string* error) const;
};

}  // namespace hw::relax
