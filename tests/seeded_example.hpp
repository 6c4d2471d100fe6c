#pragma once
// The paper-001 example as the engine's end-to-end tests use it: a seeded recording's outer set D^ss(n) in the
// prior box [-box, box]^8, and a parameter's index in a summary.
#include <algorithm>
#include <cstdint>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "core/cerone_example.hpp"
#include "dss/hw_outer_set.hpp"
#include "dss/set_membership.hpp"

namespace hw::dss {

inline HwOuterSet SeededSet(uint64_t seed, int samples, int horizon, double snr_db, double box = 10.0) {
  const auto ex = SimulateCeroneExample(seed, samples, snr_db);
  HwData data{ex.u, ex.y, std::vector<double>(ex.y.size(), ex.noise_bound), "seeded"};
  return HwOuterSet(CeroneExampleStructure(), data, horizon, std::vector<std::pair<double, double>>(8, {-box, box}));
}

inline std::size_t ParameterIndex(const BoundsSummary& summary, const std::string& name) {
  return std::find(summary.parameter_names.begin(), summary.parameter_names.end(), name) -
         summary.parameter_names.begin();
}

// For two runs of the same problem: every endpoint x of `with` is guaranteed and verified, each interval of `with`
// contains the truth, and check(name, k, x, y, is_lower) compares x with its counterpart y in `without`.
template <class Check>
void CompareEndpoints(const BoundsSummary& with, const BoundsSummary& without, const Check& check) {
  const auto truth = CeroneExample::TrueParameters();
  ASSERT_EQ(with.intervals.size(), without.intervals.size());
  for (std::size_t i = 0; i < with.intervals.size(); ++i) {
    const auto& a = with.intervals[i];
    const auto& b = without.intervals[i];
    const std::size_t k = ParameterIndex(with, a.name);
    for (const auto& [x, y, lower] : {std::tuple{a.lower, b.lower, true}, std::tuple{a.upper, b.upper, false}}) {
      EXPECT_EQ(x.status, "guaranteed") << a.name << (lower ? " lower" : " upper");
      EXPECT_EQ(x.verification, "verified") << a.name << (lower ? " lower" : " upper");
      check(a.name, k, x, y, lower);
    }
    EXPECT_LE(a.lower.value, truth[k]) << a.name;
    EXPECT_GE(a.upper.value, truth[k]) << a.name;
  }
}

}  // namespace hw::dss
