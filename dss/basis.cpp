#include "dss/basis.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include <fmt/format.h>

#include "core/csv_table.hpp"

namespace hw::dss {

std::pair<double, double> BasisFunction::range(double lo, double hi) const {
  double mn = std::min(value(lo), value(hi)), mx = std::max(value(lo), value(hi));
  for (double s : stationary_points(lo, hi)) {
    if (s <= lo || s >= hi) continue;
    mn = std::min(mn, value(s));
    mx = std::max(mx, value(s));
  }
  return {mn, mx};
}

BasisFunction power_basis(int k) {
  BasisFunction f;
  f.name = k == 1 ? "w" : fmt::format("w^{}", k);
  f.value = [k](double w) { return std::pow(w, k); };
  f.stationary_points = [k](double, double) { return k >= 2 ? std::vector<double>{0.0} : std::vector<double>{}; };
  return f;
}

namespace {

// Points a + period * m inside (lo, hi).
std::vector<double> periodic_points(double a, double period, double lo, double hi) {
  std::vector<double> pts;
  for (double m = std::ceil((lo - a) / period); a + m * period < hi; m += 1.0) pts.push_back(a + m * period);
  return pts;
}

std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t");
  const auto e = s.find_last_not_of(" \t");
  return b == std::string::npos ? "" : s.substr(b, e - b + 1);
}

}  // namespace

std::vector<BasisFunction> parse_basis(const std::string& text) {
  const std::string accepted = "accepted: 'poly:K' (w..w^K) or a comma list of w, w^k, tanh, sin, cos, exp, atan";
  std::vector<BasisFunction> out;
  if (text.rfind("poly:", 0) == 0) {
    int k = 0;
    try {
      k = std::stoi(text.substr(5));
    } catch (...) {
    }
    if (k < 1 || k > 12) throw InputError(fmt::format("basis '{}': degree must be 1..12; {}", text, accepted));
    for (int i = 1; i <= k; ++i) out.push_back(power_basis(i));
    return out;
  }
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, ',')) {
    item = trim(item);
    BasisFunction f;
    f.name = item;
    if (item == "w") {
      f = power_basis(1);
    } else if (item.rfind("w^", 0) == 0) {
      int k = 0;
      try {
        k = std::stoi(item.substr(2));
      } catch (...) {
      }
      if (k < 1 || k > 12) throw InputError(fmt::format("basis item '{}': power must be 1..12; {}", item, accepted));
      f = power_basis(k);
    } else if (item == "tanh") {
      f.value = [](double w) { return std::tanh(w); };
      f.stationary_points = [](double, double) { return std::vector<double>{}; };
    } else if (item == "atan") {
      f.value = [](double w) { return std::atan(w); };
      f.stationary_points = [](double, double) { return std::vector<double>{}; };
    } else if (item == "exp") {
      f.value = [](double w) { return std::exp(w); };
      f.stationary_points = [](double, double) { return std::vector<double>{}; };
    } else if (item == "sin") {
      f.value = [](double w) { return std::sin(w); };
      f.stationary_points = [](double lo, double hi) { return periodic_points(M_PI / 2, M_PI, lo, hi); };
    } else if (item == "cos") {
      f.value = [](double w) { return std::cos(w); };
      f.stationary_points = [](double lo, double hi) { return periodic_points(0.0, M_PI, lo, hi); };
    } else {
      throw InputError(fmt::format("basis item '{}' unknown; {}", item, accepted));
    }
    out.push_back(f);
  }
  if (out.empty()) throw InputError(fmt::format("empty basis '{}'; {}", text, accepted));
  return out;
}

}  // namespace hw::dss
