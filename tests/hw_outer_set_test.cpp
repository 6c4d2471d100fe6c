// The outer set D^ss(n) must contain the true parameters for every noise realisation (Result 1/2);
// checked directly on the polynomial inequalities, no SDP involved.
#include <gtest/gtest.h>

#include "core/cerone_example.hpp"
#include "core/csv_table.hpp"
#include "dss/hw_outer_set.hpp"

namespace hw::dss {
namespace {

HwData FromExample(const CeroneExample& ex) {
  return {ex.u, ex.y, std::vector<double>(ex.y.size(), ex.noise_bound), "example"};
}

std::vector<std::pair<double, double>> Box(int n) { return std::vector<std::pair<double, double>>(n, {-10, 10}); }

TEST(HwOuterSet, ExampleHasPaperSnr) {
  auto ex = SimulateCeroneExample(7, 1000);
  EXPECT_NEAR(ex.snr_db, 31.0, 0.5);
  EXPECT_NEAR(CeroneOutputMap(1 + 0.8 + 3.2), 1.0, 1e-12);
}

TEST(HwOuterSet, TrueParametersSatisfyEveryInequality) {
  for (int horizon = 1; horizon <= 3; ++horizon) {
    for (uint64_t seed : {1u, 2u, 3u}) {
      auto ex = SimulateCeroneExample(seed, 200);
      HwOuterSet set(CeroneExampleStructure(), FromExample(ex), horizon, Box(8));
      const auto p = CeroneExample::TrueParameters();
      EXPECT_GE(set.min_slack(p), -1e-9) << "horizon " << horizon << " seed " << seed;
      // Scaled constraints of the true orthant hold at the scaled true point too.
      const int l = set.orthant_of(p);
      std::vector<double> ps(p.size());
      for (std::size_t i = 0; i < p.size(); ++i) ps[i] = (p[i] - set.scaling().center[i]) / set.scaling().radius[i];
      for (const auto& c : set.data_constraints(l)) ASSERT_GE(c.g.evaluate(ps), -1e-9);
      for (const auto& g : set.sign_constraints(l)) ASSERT_GE(g.evaluate(ps), -1e-12);
    }
  }
}

TEST(HwOuterSet, SignVectorSizeAndDegrees) {
  auto ex = SimulateCeroneExample(1, 100);
  HwOuterSet set(CeroneExampleStructure(), FromExample(ex), 3, Box(8));
  EXPECT_EQ(set.sign_polynomials().size(), 2u + 3u * 2u);  // alpha2, alpha3, Q_{s,h}
  EXPECT_EQ(set.num_orthants(), 256);
  int max_deg = 0;
  for (const auto& c : set.data_constraints(0)) max_deg = std::max(max_deg, c.g.degree());
  EXPECT_EQ(max_deg, 4);  // n + 1 (Property 1)
  // Q_{2,h} = -[A^2](1,h) with A = [-a; I 0]: Q_{2,1} = a2 - a1^2, Q_{2,2} = -a1 a2.
  const std::vector<double> p = {0, 0, 0, 0, 1.8, 0.9, 0, 0};
  EXPECT_NEAR(set.sign_polynomials()[4].evaluate(p), 0.9 - 1.8 * 1.8, 1e-12);
  EXPECT_NEAR(set.sign_polynomials()[5].evaluate(p), -1.8 * 0.9, 1e-12);
}

TEST(HwOuterSet, BadInputIsRejectedClearly) {
  HwData d{{1, 2, 3}, {1, 2, 3}, {0.1, 0.1, 0.1}, "rec.csv"};
  EXPECT_THROW(HwOuterSet(CeroneExampleStructure(), d, 2, Box(8)), InputError);  // too short
  HwData bad{{1, 2}, {1, 2}, {0.1, -1}, "rec.csv"};
  std::string err;
  EXPECT_FALSE(bad.IsValid(&err));
  EXPECT_NE(err.find("sample 2"), std::string::npos);
}

}  // namespace
}  // namespace hw::dss
