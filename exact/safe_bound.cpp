#include "exact/safe_bound.hpp"

#include <cmath>
#include <stdexcept>

#include "exact/interval.hpp"

namespace hw::exact {

double SafeLowerBound(const LpProblem& problem, const std::vector<double>& duals, const std::vector<double>& objective) {
  const std::vector<double>& c = objective.empty() ? problem.obj : objective;
  if (static_cast<int>(duals.size()) != problem.num_rows() || static_cast<int>(c.size()) != problem.num_cols())
    throw std::invalid_argument("SafeLowerBound: dual or objective size does not match the problem");
  // Clamp each dual to the side whose row bound is finite; that side's bound enters the sum.
  std::vector<double> y(duals);
  Interval total(0.0);
  for (int i = 0; i < problem.num_rows(); ++i) {
    if (!std::isfinite(y[i])) y[i] = 0.0;
    if (y[i] > 0.0 && std::isfinite(problem.row_lo[i])) {
      const Interval lo(RoundDown(problem.row_lo[i] - problem.row_lo_radius[i]));
      total += Interval(y[i]) * lo;
    } else if (y[i] < 0.0 && std::isfinite(problem.row_hi[i])) {
      const Interval hi(RoundUp(problem.row_hi[i] + problem.row_hi_radius[i]));
      total += Interval(y[i]) * hi;
    } else {
      y[i] = 0.0;
    }
  }
  std::vector<Interval> reduced(c.begin(), c.end());
  for (const auto& e : problem.entries) {
    if (y[e.row] == 0.0) continue;
    const Interval a(RoundDown(e.value - e.radius), RoundUp(e.value + e.radius));
    reduced[e.col] = reduced[e.col] - Interval(y[e.row]) * a;
  }
  for (int j = 0; j < problem.num_cols(); ++j) total += reduced[j] * Interval(problem.col_lo[j], problem.col_hi[j]);
  return total.lo;
}

}  // namespace hw::exact
