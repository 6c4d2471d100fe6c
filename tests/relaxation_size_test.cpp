// The memory model of pop/relaxation_size.hpp against measured peak resident memory.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "pop/relaxation_size.hpp"

namespace hw::pop {
namespace {

// Peak resident memory of `hwbounds pop PROBLEM --order K --solver S` minus that of the same command at
// order 1 (the process itself), in bytes; measured by benchmarks/relaxation_memory.sh (GNU time's %M).
// p1: 1 variable, two degree-1 inequalities; p2: 2 variables, one disc; p3: 3 variables, one ball.
struct MeasuredPeak {
  std::string problem, solver;
  int num_vars, order;
  std::vector<int> inequality_degrees;
  double bytes;
};

const std::vector<MeasuredPeak>& Measurements() {
  static const std::vector<MeasuredPeak> peaks = {
      {"p1", "csdp", 1, 200, {1, 1}, 28.6e6}, {"p2", "csdp", 2, 20, {2}, 24.5e6},
      {"p2", "csdp", 2, 30, {2}, 116e6},      {"p3", "csdp", 3, 8, {2}, 17.0e6},
      {"p1", "sdpa", 1, 200, {1, 1}, 26.6e6}, {"p2", "sdpa", 2, 20, {2}, 27.6e6},
      {"p3", "sdpa", 3, 8, {2}, 17.9e6},      {"p1", "dsdp", 1, 200, {1, 1}, 138e6},
      {"p2", "dsdp", 2, 20, {2}, 65.3e6},     {"p3", "dsdp", 3, 8, {2}, 20.6e6},
  };
  return peaks;
}

// A refusal must not let through a relaxation that does not fit, so the estimate may exceed the peak
// (DSDP's dense per-moment data is not modelled exactly) but not fall far below it.
TEST(RelaxationSize, EstimateIsWithinAFactorOfTheMeasuredPeak) {
  for (const auto& m : Measurements()) {
    const auto size = EstimateRelaxationSize(m.num_vars, m.order, m.inequality_degrees, {}, m.solver);
    const double ratio = size.bytes / m.bytes;
    EXPECT_GE(ratio, 0.9) << m.problem << " order " << m.order << " " << m.solver << ": estimate " << size.bytes;
    EXPECT_LE(ratio, 3.0) << m.problem << " order " << m.order << " " << m.solver << ": estimate " << size.bytes;
  }
}

TEST(RelaxationSize, CountsMomentsAndBlocks) {
  // 3 variables, order 8: C(19, 3) - 1 = 968 moments, a 165 x 165 moment matrix, a ball's 120 x 120 localizer.
  const auto size = EstimateRelaxationSize(3, 8, {2}, {});
  EXPECT_EQ(size.moments, 968);
  EXPECT_EQ(size.moment_block, 165);
  ASSERT_EQ(size.localizing_blocks.size(), 1u);
  EXPECT_EQ(size.localizing_blocks[0], 120);
  EXPECT_GT(EstimateRelaxationSize(3, 8, {2}, {}, "dsdp").bytes, size.bytes);
}

}  // namespace
}  // namespace hw::pop
