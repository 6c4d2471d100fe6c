// The exact membership LP and the inner hull of D (exact/membership.hpp, exact/inner_hull.hpp) on the paper-001
// example: membership time (median of repeats) and the inner hull from the truth with its time, for several N.
// A timing harness, not a test.
//   exact_inner_bench [--samples 300,1000,3000,10000] [--snr 31] [--seed 1] [--restarts 0] [--repeats 5]
#include <algorithm>
#include <chrono>

#include <CLI/CLI.hpp>
#include <fmt/format.h>
#include <fmt/ranges.h>

#include "core/cerone_example.hpp"
#include "exact/inner_hull.hpp"
#include "exact/lifted_lp.hpp"
#include "exact/lp_solver.hpp"
#include "exact/membership.hpp"
#include "dss/hw_outer_set.hpp"

namespace {

double Seconds(std::chrono::steady_clock::time_point since) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - since).count();
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Exact membership and inner hull of D on the paper-001 example"};
  std::vector<int> samples{300, 1000, 3000, 10000};
  double snr = 31.0, time_limit = 600.0;
  int seed = 1, restarts = 0, repeats = 5;
  bool print_points = false;
  app.add_option("--samples", samples)->delimiter(',');
  app.add_option("--snr", snr, "SNR_w in dB (31 is the paper's)");
  app.add_option("--seed", seed);
  app.add_option("--restarts", restarts, "extra local starts per objective");
  app.add_option("--repeats", repeats, "membership checks timed per N (median reported)")->check(CLI::PositiveNumber);
  app.add_option("--time-limit", time_limit, "seconds per inner hull");
  app.add_flag("--points", print_points, "print every certified point of D (layout order)");
  CLI11_PARSE(app, argc, argv);
  const auto truth = hw::CeroneExample::TrueParameters();
  auto solver = hw::exact::MakeLpSolver("clp");
  for (int N : samples) {
    const auto ex = hw::SimulateCeroneExample(seed, N, snr);
    hw::dss::HwData data{ex.u, ex.y, std::vector<double>(ex.y.size(), ex.noise_bound), "bench"};
    const auto lifted = hw::exact::MakeLiftedData(hw::dss::CeroneExampleStructure(), data);
    std::vector<double> times;
    double slack = 0.0;
    for (int r = 0; r < repeats; ++r) {
      const auto start = std::chrono::steady_clock::now();
      slack = hw::exact::CheckMembership(lifted, truth, *solver).slack;
      times.push_back(Seconds(start));
    }
    std::sort(times.begin(), times.end());
    fmt::print("N {}: membership of the truth: slack {:.4g}, median {:.4f} s over {}\n", N, slack,
               times[times.size() / 2], repeats);
    hw::exact::ParamBox box(8, hw::exact::Interval(-10.0, 10.0));
    box[4] = hw::exact::Interval(1.79, 1.81);
    box[5] = hw::exact::Interval(0.89, 0.91);
    hw::exact::InnerHullOptions options;
    options.restarts = restarts;
    options.time_limit_seconds = time_limit;
    const auto hull = hw::exact::ComputeInnerHull(lifted, box, truth, options, *solver);
    for (int k = 0; k < 8; ++k) {
      if (!hull.ranges[k]) {
        fmt::print("  {:>7} none\n", lifted.layout.names[k]);
        continue;
      }
      fmt::print("  {:>7} [{:.6f}, {:.6f}]\n", lifted.layout.names[k], hull.ranges[k]->first, hull.ranges[k]->second);
    }
    if (print_points)
      for (const auto& p : hull.points) fmt::print("  point ({}): {:.7f}\n", p.objective, fmt::join(p.theta, " "));
    fmt::print("  inner hull: {} local solves, {} points, {:.1f} s\n", hull.local_solves, hull.points.size(),
               hull.seconds);
  }
  return 0;
}
