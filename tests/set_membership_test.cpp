// Set-membership engine on small seeded instances of the paper-001 example: the truth lies inside every
// interval (Property 2), tighter data shrink the intervals, and failures never drop an orthant.
#include <algorithm>
#include <cmath>

#include <gtest/gtest.h>

#include "core/cerone_example.hpp"
#include "core/input_error.hpp"
#include "dss/set_membership.hpp"

namespace hw::dss {
namespace {

BoundsSummary RunBounds(uint64_t seed, int samples, int horizon, int order, double snr_db, const std::string& solver = "sdpa",
                  std::vector<std::string> params = {}, bool retry = false) {
  const double box = 10.0;
  const auto ex = SimulateCeroneExample(seed, samples, snr_db);
  HwData data{ex.u, ex.y, std::vector<double>(ex.y.size(), ex.noise_bound), "seeded"};
  HwOuterSet set(CeroneExampleStructure(), data, horizon, std::vector<std::pair<double, double>>(8, {-box, box}));
  BoundsOptions options;
  options.order = order;
  options.solver = solver;
  options.threads = 2;
  options.parameters = params;
  // Retrying failed rounds with the other backend can multiply a test's run time; the CI tests keep the
  // single-backend configuration whose run time was measured (about 5 minutes for the n = 2 test).
  options.generation.retry_undecided_rounds = retry;
  return ComputeBounds(options, set);
}

void ExpectCoverage(const BoundsSummary& s, const std::string& label) {
  const auto truth = CeroneExample::TrueParameters();
  for (const auto& iv : s.intervals) {
    const std::size_t k = std::find(s.parameter_names.begin(), s.parameter_names.end(), iv.name) - s.parameter_names.begin();
    ASSERT_LT(k, truth.size());
    EXPECT_NE(iv.lower.status, EndpointStatus::kEmpty) << label;
    EXPECT_LE(iv.lower.value, truth[k] + 1e-6) << label << " " << iv.name;
    EXPECT_GE(iv.upper.value, truth[k] - 1e-6) << label << " " << iv.name;
  }
  // The true orthant is never reported empty.
  EXPECT_GE(s.orthants_solved + s.orthants_failed, 1) << label;
}

TEST(SetMembership, CoversTruthOnTwentySeededInstancesHorizon1) {
  for (uint64_t seed = 1; seed <= 20; ++seed) {
    const auto s = RunBounds(seed, 40, 1, 1, 31.0);
    ExpectCoverage(s, "seed " + std::to_string(seed));
  }
}

// One interval (a1) to keep CI short; N = 120 lets the LP screen empty most orthants. The noisy and the nearly
// noise-free runs are separate tests. The noisy run uses the default backend ("auto": CSDP at order 2), on which
// it takes a third of SDPA's time (SDPA stops short on its rounds and re-solves two endpoints); SDPA at n = 2 is
// the nearly noise-free test's.
TEST(SetMembership, Horizon2Order2CoversTruth) {
  const auto noisy = RunBounds(101, 120, 2, 2, 31.0, "auto", {"a1"});
  ASSERT_EQ(noisy.intervals.size(), 1u);
  ExpectCoverage(noisy, "n=2 seed 101, 31 dB");
}

TEST(SetMembership, Horizon2Order2TinyNoiseGivesANarrowIntervalAroundTheTruth) {
  // Nearly noise-free data (80 dB, the same input as above): the interval must close in on a1 = 1.8, to within
  // 5 % of it on each side (at 31 dB the same data leave it several tenths wide).
  const auto clean = RunBounds(101, 120, 2, 2, 80.0, "sdpa", {"a1"});
  ASSERT_EQ(clean.intervals.size(), 1u);
  ExpectCoverage(clean, "n=2 seed 101, 80 dB");
  // Narrowness is only meaningful for solved endpoints: a failed solve is widened to the box (valid, but not
  // comparable). Such a run is reported as skipped, with the solver's notes, never as passed.
  const auto& iv = clean.intervals[0];
  if (iv.lower.status != EndpointStatus::kGuaranteed || iv.upper.status != EndpointStatus::kGuaranteed)
    GTEST_SKIP() << "a solve failed and fell back to a conservative bound; width not checked. notes: " << iv.lower.note
                 << " | " << iv.upper.note;
  EXPECT_LT(iv.half_width(), 0.05 * 1.8) << "a1 at 80 dB: [" << iv.lower.value << ", " << iv.upper.value << "]";
}

TEST(SetMembership, SameEndpointsWhateverTheNumberOfWorkers) {
  // Job results depend only on their specs (deterministic warm starts), never on which worker ran them or when.
  const auto ex = SimulateCeroneExample(3, 60, 31.0);
  HwData data{ex.u, ex.y, std::vector<double>(ex.y.size(), ex.noise_bound), "seeded"};
  HwOuterSet set(CeroneExampleStructure(), data, 1, std::vector<std::pair<double, double>>(8, {-10.0, 10.0}));
  BoundsOptions options;
  options.order = 1;
  options.generation.retry_undecided_rounds = false;
  options.executor = std::make_shared<sdp::ForkExecutor>(1);
  const auto one = ComputeBounds(options, set);
  options.executor = std::make_shared<sdp::ForkExecutor>(2);
  const auto two = ComputeBounds(options, set);
  options.executor = std::make_shared<sdp::InProcessExecutor>();
  const auto here = ComputeBounds(options, set);
  ASSERT_EQ(one.intervals.size(), two.intervals.size());
  for (std::size_t k = 0; k < one.intervals.size(); ++k)
    for (const auto* other : {&two, &here}) {
      EXPECT_NEAR(one.intervals[k].lower.value, other->intervals[k].lower.value, 1e-9) << one.intervals[k].name;
      EXPECT_NEAR(one.intervals[k].upper.value, other->intervals[k].upper.value, 1e-9) << one.intervals[k].name;
    }
}

TEST(SetMembership, UnknownParameterNameIsAnError) {
  EXPECT_THROW(RunBounds(1, 40, 1, 1, 31.0, "sdpa", {"a7"}), InputError);
}

TEST(SetMembership, CsdpAndSdpaGiveTheSameIntervals) {
  const auto a = RunBounds(9, 30, 1, 1, 31.0, "csdp");
  const auto b = RunBounds(9, 30, 1, 1, 31.0, "sdpa");
  for (std::size_t k = 0; k < a.intervals.size(); ++k) {
    EXPECT_NEAR(a.intervals[k].lower.value, b.intervals[k].lower.value, 1e-4);
    EXPECT_NEAR(a.intervals[k].upper.value, b.intervals[k].upper.value, 1e-4);
  }
}

}  // namespace
}  // namespace hw::dss
