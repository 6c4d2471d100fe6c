#pragma once
// Known univariate basis functions of the static blocks (psi_i of the input map, phi_j of the
// inverse output map), with their exact range over an interval (paper 001, Remark 2: the extremes
// of a continuous univariate function lie at stationary points or at the interval's ends).
#include <functional>
#include <string>
#include <vector>

namespace hw::dss {

struct BasisFunction {
  std::string name;
  std::function<double(double)> value;
  // Stationary points inside (lo, hi); with the endpoints they give the range exactly.
  std::function<std::vector<double>(double lo, double hi)> stationary_points;

  // [min, max] of the function over [lo, hi].
  std::pair<double, double> range(double lo, double hi) const;
};

// Parses a basis description:
//   "poly:K"            -> w, w^2, ..., w^K
//   "w,w^3,tanh,sin"    -> an explicit list; items: w^k (k >= 1), tanh, sin, cos, exp, atan
// Throws hw::InputError with the offending item and the accepted forms.
std::vector<BasisFunction> parse_basis(const std::string& text);
BasisFunction power_basis(int k);

}  // namespace hw::dss
