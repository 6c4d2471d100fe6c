#pragma once
// Isolated gross errors (a spike, a corrupted sample) in the recordings Brouri's method averages. An
// average of M samples moves by outlier / M, so one 1e6 in a hold of y ~ 1 ruins the hold; the averages
// therefore leave out samples that lie far outside the noise and flag them by sample.
#include <cstddef>
#include <vector>

namespace hw::brouri {

// A sample is an outlier when it lies more than kOutlierSigmas robust standard deviations (1.4826 times the
// median absolute deviation) from its reference median, and more than kOutlierFloor times the data's scale
// (so that noise-free recordings are never trimmed for rounding-level differences).
constexpr double kOutlierSigmas = 10.0;
constexpr double kOutlierFloor = 1e-3;

double Median(std::vector<double> v);
double RobustSigma(const std::vector<double>& v);  // 1.4826 * median |v - median(v)|

// Indices i in [first, end) of isolated outliers of y around `median`: runs of at most two consecutive samples
// beyond `threshold` whose neighbours lie within half of it, the one before them in the same range (a run
// that starts the range is a transient after a level change, not an outlier).
std::vector<std::size_t> IsolatedOutliers(const std::vector<double>& y, std::size_t first, std::size_t end,
                                          double median, double threshold);

}  // namespace hw::brouri
