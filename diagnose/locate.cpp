#include "diagnose/locate.hpp"

#include <algorithm>
#include <cmath>

namespace hw::diagnose {

std::vector<bool> BlockEffectMask(const AugmentedModel& m, const std::vector<double>& u, double sigma,
                                  std::size_t skip, std::vector<double>* difference) {
  const std::vector<double> with = m.simulate(u), without = m.WithoutBlocks().simulate(u);
  std::vector<bool> mask(u.size(), false);
  if (difference) difference->assign(u.size(), 0.0);
  for (std::size_t t = 0; t < u.size(); ++t) {
    const double d = with[t] - without[t];
    if (difference) (*difference)[t] = d;
    mask[t] = t >= skip && std::abs(d) > sigma;
  }
  return mask;
}

double IntersectionOverUnion(const std::vector<bool>& a, const std::vector<bool>& b, std::size_t skip) {
  std::size_t both = 0, either = 0;
  for (std::size_t t = skip; t < std::min(a.size(), b.size()); ++t) {
    both += a[t] && b[t];
    either += a[t] || b[t];
  }
  return either == 0 ? 1.0 : static_cast<double>(both) / either;
}

double ImprovementShareIn(const std::vector<bool>& mask, const std::vector<double>& e0, const std::vector<double>& e1,
                          std::size_t from, std::size_t to) {
  double in = 0.0, all = 0.0;
  for (std::size_t t = from; t < to && t < mask.size(); ++t) {
    const double d = e0[t] * e0[t] - e1[t] * e1[t];
    all += d;
    if (mask[t]) in += d;
  }
  return all > 0 ? in / all : 0.0;
}

}  // namespace hw::diagnose
