#pragma once
// A linear program in the form the exact-set engine builds and certifies:
//   minimise obj' x   subject to   row_lo <= A x <= row_hi,   col_lo <= x <= col_hi,
// with finite column bounds (the safe bound needs them) and coefficients known only up to a radius: every
// stored number is the midpoint of an interval that contains the exact coefficient (basis values of data
// points are computed in floating point). The certificate (exact/safe_bound.hpp) uses the radii.
#include <cstdint>
#include <string>
#include <vector>

namespace hw::exact {

struct LpEntry {
  int row = 0, col = 0;
  double value = 0.0;
  double radius = 0.0;  // |exact coefficient - value| <= radius
};

struct LpProblem {
  std::vector<double> col_lo, col_hi, obj;
  std::vector<double> row_lo, row_hi;  // -inf / +inf for a one-sided row
  std::vector<double> row_lo_radius, row_hi_radius;
  std::vector<LpEntry> entries;

  int num_cols() const { return static_cast<int>(col_lo.size()); }
  int num_rows() const { return static_cast<int>(row_lo.size()); }
  int AddColumn(double lo, double hi);
  // A row lo <= sum value_k x_k <= hi; returns its index. The entries are added with AddEntry.
  int AddRow(double lo, double hi, double lo_radius = 0.0, double hi_radius = 0.0);
  void AddEntry(int row, int col, double value, double radius = 0.0) { entries.push_back({row, col, value, radius}); }
  // False with the first problem found (sizes, a NaN, an infinite column bound, a crossed bound) in *error.
  bool IsValid(std::string* error) const;
};

// A simplex basis: one status byte per column then per row, in the LP backend's own coding. It warm-starts a
// problem of the same shape (a child box has the parent's rows and columns with other coefficients).
struct LpBasis {
  std::vector<std::uint8_t> status;
  bool empty() const { return status.empty(); }
};

}  // namespace hw::exact
