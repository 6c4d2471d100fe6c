#include "estimators/brouri/outliers.hpp"

#include <algorithm>
#include <cmath>

namespace hw::brouri {

double Median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  const std::size_t k = v.size() / 2;
  std::nth_element(v.begin(), v.begin() + k, v.end());
  const double hi = v[k];
  if (v.size() % 2) return hi;
  return 0.5 * (hi + *std::max_element(v.begin(), v.begin() + k));
}

double RobustSigma(const std::vector<double>& v) {
  const double m = Median(v);
  std::vector<double> dev(v.size());
  for (std::size_t i = 0; i < v.size(); ++i) dev[i] = std::abs(v[i] - m);
  return 1.4826 * Median(std::move(dev));
}

std::vector<std::size_t> IsolatedOutliers(const std::vector<double>& y, std::size_t first, std::size_t end,
                                          double median, double threshold) {
  constexpr std::size_t kMaxRun = 2;
  // The samples around a run must lie well inside the threshold: a smooth transient that hovers near the
  // threshold while noise carries single samples across it is no outlier.
  auto calm = [&](std::size_t k) { return std::abs(y[k] - median) <= 0.5 * threshold; };
  std::vector<std::size_t> out;
  for (std::size_t i = first; i < end;) {
    if (!(std::abs(y[i] - median) > threshold)) {
      ++i;
      continue;
    }
    std::size_t j = i;
    while (j < end && std::abs(y[j] - median) > threshold) ++j;
    if (i > first && j - i <= kMaxRun && calm(i - 1) && (j == end || calm(j)))
      for (std::size_t k = i; k < j; ++k) out.push_back(k);
    i = j;
  }
  return out;
}

}  // namespace hw::brouri
