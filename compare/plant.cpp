#include "compare/plant.hpp"

#include <cmath>
#include <limits>

namespace hw::compare {

double PolyNoConstant(const std::vector<double>& c, double v) {
  double acc = 0.0;
  for (std::size_t k = c.size(); k-- > 0;) acc = (acc + c[k]) * v;
  return acc;
}

static double PolyDerivative(const std::vector<double>& c, double v) {
  double acc = 0.0, p = 1.0;
  for (std::size_t k = 0; k < c.size(); ++k) {
    acc += (k + 1) * c[k] * p;
    p *= v;
  }
  return acc;
}

bool Plant::inverse_monotone(double w_lo, double w_hi, int n) const {
  if (inverse_output.empty()) return true;
  double sign = 0.0;
  for (int i = 0; i < n; ++i) {
    const double d = PolyDerivative(inverse_output, w_lo + (w_hi - w_lo) * i / (n - 1));
    if (!(std::abs(d) > 0)) return false;
    if (sign == 0.0) sign = d > 0 ? 1 : -1;
    if (d * sign <= 0) return false;
  }
  return true;
}

std::optional<double> Plant::output(double z) const {
  if (inverse_output.empty()) return model.output(z);
  // Bisection on a bracket grown from [-1, 1]; the direction comes from the derivative at 0 (alpha_1).
  const auto& c = inverse_output;
  const double dir = PolyDerivative(c, 0.0) >= 0 ? 1.0 : -1.0;
  auto f = [&](double w) { return dir * (PolyNoConstant(c, w) - z); };
  double lo = -1.0, hi = 1.0;
  for (int i = 0; i < 60 && f(lo) > 0; ++i) lo *= 2;
  for (int i = 0; i < 60 && f(hi) < 0; ++i) hi *= 2;
  if (f(lo) > 0 || f(hi) < 0) return std::nullopt;
  for (int it = 0; it < 200 && hi - lo > 1e-14 * std::max(1.0, std::abs(lo)); ++it) {
    const double mid = 0.5 * (lo + hi);
    (f(mid) > 0 ? hi : lo) = mid;
  }
  const double w = 0.5 * (lo + hi);
  // Unique only where the polynomial is monotone around the root found.
  const double span = std::max(1e-3, 0.05 * std::abs(w));
  if (!inverse_monotone(w - span, w + span, 21)) return std::nullopt;
  return w;
}

std::complex<double> FrequencyResponse(const LinearBlock& lin, double omega) {
  using C = std::complex<double>;
  C num = 0.0, den = 1.0;
  for (std::size_t j = 0; j < lin.b.size(); ++j) num += lin.b[j] * std::polar(1.0, -omega * double(lin.delay + j));
  for (std::size_t i = 0; i < lin.a.size(); ++i) den += lin.a[i] * std::polar(1.0, -omega * double(i + 1));
  return num / den;
}

double Plant::static_gain() const { return FrequencyResponse(model.linear, 0.0).real(); }

std::optional<double> Plant::steady_state(double u) const { return output(static_gain() * model.input(u)); }

double Plant::normalised_gain(double omega) const {
  return std::abs(FrequencyResponse(model.linear, omega)) / std::abs(static_gain());
}

std::vector<double> Plant::simulate(const std::vector<double>& u, int warmup) const {
  if (u.empty()) return {};
  std::vector<double> ext(warmup, u.front());
  ext.insert(ext.end(), u.begin(), u.end());
  std::vector<double> x(ext.size());
  for (std::size_t t = 0; t < ext.size(); ++t) x[t] = model.input(ext[t]);
  const auto z = model.linear.simulate(x);
  std::vector<double> w;
  w.reserve(u.size());
  for (std::size_t t = warmup; t < z.size(); ++t) {
    const auto v = output(z[t]);
    if (!v || !std::isfinite(*v)) return {};
    w.push_back(*v);
  }
  return w;
}

}  // namespace hw::compare
