#pragma once
// The paper-001 example as the engine's end-to-end tests use it: a seeded recording's outer set D^ss(n) in the
// prior box [-box, box]^8, and a parameter's index in a summary.
#include <algorithm>
#include <cstdint>
#include <string>
#include <vector>

#include "core/cerone_example.hpp"
#include "relax/hw_outer_set.hpp"
#include "relax/set_membership.hpp"

namespace hw::relax {

inline HwOuterSet SeededSet(uint64_t seed, int samples, int horizon, double snr_db, double box = 10.0) {
  const auto ex = SimulateCeroneExample(seed, samples, snr_db);
  HwData data{ex.u, ex.y, std::vector<double>(ex.y.size(), ex.noise_bound), "seeded"};
  return HwOuterSet(CeroneExampleStructure(), data, horizon, std::vector<std::pair<double, double>>(8, {-box, box}));
}

inline std::size_t ParameterIndex(const BoundsSummary& summary, const std::string& name) {
  return std::find(summary.parameter_names.begin(), summary.parameter_names.end(), name) -
         summary.parameter_names.begin();
}

}  // namespace hw::relax
