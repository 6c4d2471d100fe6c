// The exact membership LP and the inner hull of D (exact/membership.hpp, exact/inner_hull.hpp).
#include <chrono>
#include <cmath>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "core/cerone_example.hpp"
#include "core/csv_table.hpp"
#include "exact/inner_hull.hpp"
#include "exact/lifted_lp.hpp"
#include "exact/lp_solver.hpp"
#include "exact/membership.hpp"
#include "random_hw.hpp"
#include "relax/hw_outer_set.hpp"

namespace hw::exact {
namespace {

LiftedData CeroneData(uint64_t seed, int samples, double snr_db) {
  const auto ex = SimulateCeroneExample(seed, samples, snr_db);
  relax::HwData data{ex.u, ex.y, std::vector<double>(ex.y.size(), ex.noise_bound), "seeded"};
  return MakeLiftedData(relax::CeroneExampleStructure(), data);
}

LiftedData BundledRecording() {
  const auto table = read_csv(std::string(HW_SOURCE_DIR) + "/paper_examples/data/cerone2011_N300.csv");
  relax::HwData data{table.column("u"), table.column("y"), table.column("noise_bound"), table.source};
  return MakeLiftedData(relax::CeroneExampleStructure(), data);
}

TEST(ExactMembership, TruthOfANearlyNoiseFreeRecordIsAMemberAndAFarPointIsNot) {
  const LiftedData data = CeroneData(3, 400, 60.0);
  auto solver = MakeLpSolver("clp");
  const auto truth = CeroneExample::TrueParameters();
  const MembershipResult in = CheckMembership(data, truth, *solver);
  EXPECT_TRUE(in.member);
  EXPECT_TRUE(in.increasing);
  EXPECT_GE(in.slack, 0.0);
  ASSERT_EQ(in.initial_state.size(), 2u);

  auto far = truth;
  far[4] = 1.7;  // a1
  const MembershipResult out = CheckMembership(data, far, *solver);
  EXPECT_FALSE(out.member);
  EXPECT_LT(out.slack, 0.0);
  EXPECT_TRUE(out.increasing);
}

TEST(ExactMembership, ADecreasingOutputMapIsNotAMember) {
  const LiftedData data = CeroneData(3, 200, 60.0);
  auto solver = MakeLpSolver("clp");
  auto theta = CeroneExample::TrueParameters();
  theta[3] = -3.2;  // alpha3 < 0: p(alpha, w) = w + 0.8 w^2 - 3.2 w^3 decreases for large |w|
  const MembershipResult r = CheckMembership(data, theta, *solver);
  EXPECT_FALSE(r.increasing);
  EXPECT_FALSE(r.member);
}

TEST(ExactMembership, AnUnstableLinearBlockIsNotAMember) {
  const LiftedData data = CeroneData(3, 300, 60.0);
  auto solver = MakeLpSolver("clp");
  auto theta = CeroneExample::TrueParameters();
  theta[5] = 1.5;  // a2: poles of modulus sqrt(1.5)
  EXPECT_FALSE(CheckMembership(data, theta, *solver).member);
}

TEST(ExactMembership, TruthOfHundredRandomSystemsIsAMember) {
  auto solver = MakeLpSolver("clp");
  for (uint64_t seed = 1; seed <= 100; ++seed) {
    const auto inst = testing::MakeRandomHwInstance(seed);
    const LiftedData data = MakeLiftedData(inst.structure, inst.data);
    const MembershipResult r = CheckMembership(data, inst.theta, *solver);
    EXPECT_TRUE(r.member) << inst.description << ": slack " << r.slack << (r.increasing ? "" : ", not increasing");
    EXPECT_GE(r.slack, 0.0) << inst.description;
  }
}

TEST(RandomHw, CoversTheStructuresAndIsAFunctionOfTheSeed) {
  int proper = 0, strictly = 0, tanh_inputs = 0, cubic_outputs = 0;
  for (uint64_t seed = 1; seed <= 100; ++seed) {
    const auto inst = testing::MakeRandomHwInstance(seed);
    const auto layout = relax::MakeLayout(inst.structure);
    ASSERT_EQ(static_cast<int>(inst.theta.size()), layout.count()) << inst.description;
    (inst.structure.strictly_proper ? strictly : proper) += 1;
    tanh_inputs += inst.structure.input_basis.size() == 2 && inst.structure.input_basis[1].name == "tanh";
    cubic_outputs += inst.structure.output_basis.size() == 3;
    for (std::size_t t = 0; t < inst.w.size(); ++t)
      ASSERT_LE(std::abs(inst.data.y[t] - inst.w[t]), inst.data.noise_bound[t]) << inst.description;
  }
  EXPECT_GT(proper, 20);
  EXPECT_GT(strictly, 20);
  EXPECT_GT(tanh_inputs, 10);
  EXPECT_GT(cubic_outputs, 10);
  const auto a = testing::MakeRandomHwInstance(7), b = testing::MakeRandomHwInstance(7);
  EXPECT_EQ(a.data.y, b.data.y);
  EXPECT_EQ(a.theta, b.theta);
}

}  // namespace
}  // namespace hw::exact
