// Whole set-membership runs (paper-001 example, 31 dB): wall time, SDP jobs and solves, median time per SDP,
// speed-up from 1 to 2 local worker processes, and growth with N. A timing harness, not a test; each
// configuration runs `repeats` times and the median wall time is printed, ratios from the same run.
//   setmembership_scale_bench [--samples 250,500,1000] [--horizon 1] [--order 1] [--workers 1,2] [--repeats 1]
//                             [--params a1,...] [--solver auto]
// Besides the timing table: data rows kept by the exact reduction (summed over live orthants, per step) and the
// intervals of the last configuration of each N.
#include <algorithm>
#include <chrono>
#include <map>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "core/cerone_example.hpp"
#include "dss/set_membership.hpp"

namespace {
// "kept/rows" per horizon step, summed over the live orthants.
std::string RowsKept(const hw::dss::BoundsSummary& s) {
  std::map<int, std::pair<int, int>> per_step;
  for (const auto& orthant : s.row_reduction)
    for (const auto& step : orthant.at("per_step")) {
      auto& [kept, rows] = per_step[step.at("step").get<int>()];
      kept += step.at("kept").get<int>();
      rows += step.at("rows").get<int>();
    }
  std::string text;
  for (const auto& [step, kr] : per_step) text += fmt::format("{}{}/{}", text.empty() ? "" : " ", kr.first, kr.second);
  return text.empty() ? "-" : text;
}

void PrintIntervals(const hw::dss::BoundsSummary& s) {
  for (const auto& iv : s.intervals)
    fmt::print("         {:<7} [{:.6f}, {:.6f}] {} / {}\n", iv.name, iv.lower.value, iv.upper.value, iv.lower.status,
               iv.upper.status);
}
}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Set-membership scale harness"};
  std::vector<int> samples{250, 500, 1000}, workers{1, 2};
  int horizon = 1, order = 1, repeats = 1;
  std::string solver = "auto";
  std::vector<std::string> params;
  app.add_option("--samples", samples)->delimiter(',');
  app.add_option("--workers", workers)->delimiter(',');
  app.add_option("--horizon", horizon);
  app.add_option("--order", order);
  app.add_option("--repeats", repeats);
  app.add_option("--solver", solver);
  app.add_option("--params", params)->delimiter(',');
  CLI11_PARSE(app, argc, argv);
  fmt::print("paper-001 example, 31 dB, n = {}, delta = {}, solver {}, params {}\n", horizon, order, solver,
             params.empty() ? "all" : fmt::format("{}", fmt::join(params, ",")));
  fmt::print("{:>6} {:>8} {:>9} {:>9} {:>8} {:>10} {:>9} {:>9} {:>12} {:>20}\n", "N", "workers", "wall s", "orthants",
             "jobs", "SDP solves", "median s", "moments", "speed-up", "rows kept per step");
  std::map<int, double> wall_1;
  for (int N : samples) {
    const auto ex = hw::SimulateCeroneExample(1, N);
    hw::dss::HwData data{ex.u, ex.y, std::vector<double>(ex.y.size(), ex.noise_bound), "bench"};
    hw::dss::HwOuterSet set(hw::dss::CeroneExampleStructure(), data, horizon,
                              std::vector<std::pair<double, double>>(8, {-10.0, 10.0}));
    for (int w : workers) {
      std::vector<double> walls;
      hw::dss::BoundsSummary s;
      for (int r = 0; r < repeats; ++r) {
        hw::dss::BoundsOptions o;
        o.order = order;
        o.solver = solver;
        o.threads = w;
        o.parameters = params;
        const auto t0 = std::chrono::steady_clock::now();
        s = hw::dss::ComputeBounds(o, set);
        walls.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
      }
      std::sort(walls.begin(), walls.end());
      const double wall = walls[walls.size() / 2];
      if (w == workers.front()) wall_1[N] = wall;
      fmt::print("{:>6} {:>8} {:>9.1f} {:>4}/{:<4} {:>8} {:>10} {:>9.3f} {:>9} {:>12.2f} {:>20}\n", N, w, wall,
                 s.orthants_total - s.orthants_empty, s.orthants_total, s.sdp_jobs, s.sdp_solves,
                 s.median_solve_seconds, s.largest_moments, wall_1[N] / wall, RowsKept(s));
      if (w == workers.back()) PrintIntervals(s);
      std::fflush(stdout);
    }
  }
}
