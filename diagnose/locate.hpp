#pragma once
// Where an effect acts: the samples where a model's effect blocks change its prediction by more than
// the noise, and how well two such sample sets agree (intersection over union).
#include <string>
#include <vector>

#include "diagnose/effects.hpp"

namespace hw::diagnose {

// mask_t = |m(u)_t - m.WithoutBlocks()(u)_t| > sigma for t >= skip; `difference` (optional) receives
// the signed change m(u) - m.WithoutBlocks()(u).
std::vector<bool> BlockEffectMask(const AugmentedModel& m, const std::vector<double>& u, double sigma,
                                  std::size_t skip, std::vector<double>* difference);

// Where each block of m (and each limit of a two-sided saturation) acts on its own: the samples where
// removing just that block (or setting just that limit to infinity) changes the prediction by more
// than sigma. Labels: "backlash@input", "state_saturation@state upper limit".
struct BlockWindows {
  std::string label;
  std::vector<bool> mask;
  double fraction = 0.0;  // of the samples after skip
};
std::vector<BlockWindows> PerBlockMasks(const AugmentedModel& m, const std::vector<double>& u, double sigma,
                                        std::size_t skip);

// |a and b| / |a or b| over t >= skip; 1 when both are empty (nothing to find, nothing flagged).
double IntersectionOverUnion(const std::vector<bool>& a, const std::vector<bool>& b, std::size_t skip);

// Share of the squared-error reduction e0^2 - e1^2 over [from, to) that falls inside mask.
double ImprovementShareIn(const std::vector<bool>& mask, const std::vector<double>& e0, const std::vector<double>& e1,
                          std::size_t from, std::size_t to);

}  // namespace hw::diagnose
