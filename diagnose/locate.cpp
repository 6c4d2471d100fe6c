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

namespace {
std::vector<bool> DifferenceMask(const std::vector<double>& a, const std::vector<double>& b, double sigma,
                                 std::size_t skip, double* fraction) {
  std::vector<bool> mask(a.size(), false);
  std::size_t k = 0;
  for (std::size_t t = skip; t < a.size(); ++t) k += mask[t] = std::abs(a[t] - b[t]) > sigma;
  *fraction = a.size() > skip ? static_cast<double>(k) / (a.size() - skip) : 0.0;
  return mask;
}
}  // namespace

std::vector<BlockWindows> PerBlockMasks(const AugmentedModel& m, const std::vector<double>& u, double sigma,
                                        std::size_t skip) {
  std::vector<BlockWindows> out;
  const std::vector<double> full = m.simulate(u);
  for (std::size_t i = 0; i < m.blocks.size(); ++i) {
    const EffectBlock& b = m.blocks[i];
    AugmentedModel without = m;
    without.blocks.erase(without.blocks.begin() + i);
    BlockWindows w;
    w.label = b.Label();
    w.mask = DifferenceMask(full, without.simulate(u), sigma, skip, &w.fraction);
    out.push_back(w);
    const bool limits = b.effect == Effect::kSaturation || b.effect == Effect::kStateSaturation;
    if (!limits || !std::isfinite(b.params[0]) || !std::isfinite(b.params[1])) continue;
    for (int side = 0; side < 2; ++side) {
      AugmentedModel one = m;
      one.blocks[i].params[side] = side == 0 ? -HUGE_VAL : HUGE_VAL;
      BlockWindows s;
      s.label = b.Label() + (side == 0 ? " lower limit" : " upper limit");
      s.mask = DifferenceMask(full, one.simulate(u), sigma, skip, &s.fraction);
      out.push_back(s);
    }
  }
  return out;
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
