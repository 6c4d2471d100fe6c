#pragma once
// A closed interval of doubles with outward rounding: every operation widens its round-to-nearest result by
// one ulp on each side, so the result contains the exact one whatever the FPU rounding mode. Used for the
// certificates of the exact-set engine (safe LP bounds, a-priori bounds of lifted variables, LP coefficients).
#include <algorithm>
#include <cmath>
#include <limits>

namespace hw::exact {

inline double RoundDown(double v) { return std::nextafter(v, -std::numeric_limits<double>::infinity()); }
inline double RoundUp(double v) { return std::nextafter(v, std::numeric_limits<double>::infinity()); }

struct Interval {
  double lo = 0.0, hi = 0.0;
  Interval() = default;
  Interval(double v) : lo(v), hi(v) {}  // NOLINT: a double is the point interval
  Interval(double l, double h) : lo(l), hi(h) {}
  double mid() const { return 0.5 * lo + 0.5 * hi; }
  double rad() const { return RoundUp(std::max(hi - mid(), mid() - lo)); }
  bool contains(double v) const { return lo <= v && v <= hi; }
  // The value v with a relative error of at most `ulps` units in the last place (e.g. a libm result).
  static Interval WithUlps(double v, double ulps) {
    const double e = ulps * std::numeric_limits<double>::epsilon() * std::abs(v) + std::numeric_limits<double>::denorm_min();
    return {RoundDown(v - e), RoundUp(v + e)};
  }
};

inline Interval operator+(Interval a, Interval b) { return {RoundDown(a.lo + b.lo), RoundUp(a.hi + b.hi)}; }
inline Interval operator-(Interval a, Interval b) { return {RoundDown(a.lo - b.hi), RoundUp(a.hi - b.lo)}; }
inline Interval operator-(Interval a) { return {-a.hi, -a.lo}; }
inline Interval operator*(Interval a, Interval b) {
  const double p[4] = {a.lo * b.lo, a.lo * b.hi, a.hi * b.lo, a.hi * b.hi};
  return {RoundDown(*std::min_element(p, p + 4)), RoundUp(*std::max_element(p, p + 4))};
}
inline Interval Hull(Interval a, Interval b) { return {std::min(a.lo, b.lo), std::max(a.hi, b.hi)}; }
inline Interval& operator+=(Interval& a, Interval b) { return a = a + b; }

}  // namespace hw::exact
