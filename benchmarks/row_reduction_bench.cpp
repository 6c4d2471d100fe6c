// Exact row reduction of the paper-001 example's data rows (dss/row_reduction.hpp) in the true orthant:
// rows kept per horizon step and time, for several N and noise levels. A timing harness, not a test.
//   row_reduction_bench [--samples 300,1000] [--horizon 2] [--snr 31] [--seed 1]
#include <chrono>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "core/cerone_example.hpp"
#include "dss/hw_outer_set.hpp"
#include "dss/row_reduction.hpp"

int main(int argc, char** argv) {
  CLI::App app{"Exact row reduction on the paper-001 example"};
  std::vector<int> samples{300, 1000};
  std::vector<double> snrs{31.0};
  int horizon = 2, seed = 1;
  app.add_option("--samples", samples)->delimiter(',');
  app.add_option("--snr", snrs, "SNR_w in dB (31 is the paper's)")->delimiter(',');
  app.add_option("--horizon", horizon);
  app.add_option("--seed", seed);
  CLI11_PARSE(app, argc, argv);
  fmt::print("{:>6} {:>6} {:>4} {:>6} {:>8} {:>8} {:>9}\n", "N", "SNR", "s", "rows", "kept", "LPs", "seconds");
  for (double snr : snrs)
    for (int N : samples) {
      const auto ex = hw::SimulateCeroneExample(seed, N, snr);
      hw::dss::HwData data{ex.u, ex.y, std::vector<double>(ex.y.size(), ex.noise_bound), "bench"};
      hw::dss::HwOuterSet set(hw::dss::CeroneExampleStructure(), data, horizon,
                                std::vector<std::pair<double, double>>(8, {-10.0, 10.0}));
      const int l = set.orthant_of(hw::CeroneExample::TrueParameters());
      std::vector<hw::Polynomial> rows, fixed = set.box_constraints();
      std::vector<int> steps;
      for (const auto& d : set.data_constraints(l)) {
        rows.push_back(d.g);
        steps.push_back(d.s);
      }
      for (auto& g : set.sign_constraints(l)) fixed.push_back(g);
      const auto r = hw::dss::ReduceDataRows({}, rows, steps, fixed);
      for (const auto& c : r.per_step)
        fmt::print("{:>6} {:>6.1f} {:>4} {:>6} {:>8} {:>8} {:>9.2f}\n", N, snr, c.step, c.rows, c.kept,
                   r.linear_programs, r.seconds);
    }
  return 0;
}
