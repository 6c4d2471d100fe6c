#include "exact/lp_problem.hpp"

#include <cmath>

#include <fmt/format.h>

namespace hw::exact {

int LpProblem::AddColumn(double lo, double hi) {
  col_lo.push_back(lo);
  col_hi.push_back(hi);
  obj.push_back(0.0);
  return num_cols() - 1;
}

int LpProblem::AddRow(double lo, double hi, double lo_radius, double hi_radius) {
  row_lo.push_back(lo);
  row_hi.push_back(hi);
  row_lo_radius.push_back(lo_radius);
  row_hi_radius.push_back(hi_radius);
  return num_rows() - 1;
}

bool LpProblem::IsValid(std::string* error) const {
  auto fail = [&](std::string m) {
    if (error) *error = std::move(m);
    return false;
  };
  if (col_hi.size() != col_lo.size() || obj.size() != col_lo.size()) return fail("LP: column arrays differ in size");
  if (row_hi.size() != row_lo.size() || row_lo_radius.size() != row_lo.size() || row_hi_radius.size() != row_lo.size())
    return fail("LP: row arrays differ in size");
  for (int j = 0; j < num_cols(); ++j) {
    if (!std::isfinite(col_lo[j]) || !std::isfinite(col_hi[j]))
      return fail(fmt::format("LP: column {} has an infinite bound [{}, {}]", j, col_lo[j], col_hi[j]));
    if (col_lo[j] > col_hi[j]) return fail(fmt::format("LP: column {} bounds cross [{}, {}]", j, col_lo[j], col_hi[j]));
    if (!std::isfinite(obj[j])) return fail(fmt::format("LP: objective coefficient {} is not finite", j));
  }
  for (int i = 0; i < num_rows(); ++i)
    if (std::isnan(row_lo[i]) || std::isnan(row_hi[i]) || row_lo[i] > row_hi[i])
      return fail(fmt::format("LP: row {} bounds [{}, {}] are not an interval", i, row_lo[i], row_hi[i]));
  for (const auto& e : entries)
    if (e.row < 0 || e.row >= num_rows() || e.col < 0 || e.col >= num_cols() || !std::isfinite(e.value) ||
        !(e.radius >= 0.0))
      return fail(fmt::format("LP: entry ({}, {}) = {} ± {} is out of range or not finite", e.row, e.col, e.value, e.radius));
  return true;
}

}  // namespace hw::exact
