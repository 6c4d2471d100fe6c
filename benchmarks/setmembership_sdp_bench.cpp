// One set-membership relaxation (paper-001 example, true orthant, min a1) with K data inequalities in
// the LMI: build and solve time of each SDP backend as K and the order grow. A timing harness, not a test.
//   setmembership_sdp_bench [--samples N] [--horizon n] [--order d] [--k 10,40,160] [--repeats R]
//                           [--solvers csdp,sdpa,dsdp] [--verbose]
// One row per (K, solver): status, wall and CPU time of Solve() (setup included; CPU time is the fair measure on
// a shared machine, the solves being single-threaded), iterations, the floating-point bound
// on a1 and the verified bound made from the returned multiplier X (sdp/verified_bound.hpp), both in original
// units, and the solver's message when the solve is not usable. A solver that does not finish cannot be
// interrupted in-process: cap each run from outside (`ulimit -t` for CPU seconds, `timeout` for wall time).
#include <algorithm>
#include <chrono>
#include <ctime>
#include <sstream>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "core/cerone_example.hpp"
#include "dss/hw_outer_set.hpp"
#include "pop/constraint_generation.hpp"
#include "pop/moment_relaxation.hpp"
#include "sdp/verified_bound.hpp"

namespace {
using Clock = std::chrono::steady_clock;
double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}
std::vector<std::string> SplitCommas(const std::string& text) {
  std::vector<std::string> out;
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, ',')) out.push_back(item);
  return out;
}
}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Set-membership SDP size/time harness"};
  int samples = 300, horizon = 2, order = 2, repeats = 1;
  bool verbose = false;
  std::string ks = "10,40,160", solvers = "csdp,sdpa,dsdp";
  app.add_option("--samples", samples);
  app.add_option("--horizon", horizon);
  app.add_option("--order", order);
  app.add_option("--k", ks);
  app.add_option("--repeats", repeats);
  app.add_option("--solvers", solvers, "comma-separated SDP backends");
  app.add_flag("--verbose", verbose, "print the solvers' iteration logs (shows how far a run cut short got)");
  CLI11_PARSE(app, argc, argv);
  const auto solver_names = SplitCommas(solvers);
  for (const auto& name : solver_names) hw::sdp::MakeSolver(name);  // unknown names fail before any work
  const auto ex = hw::SimulateCeroneExample(1, samples);
  const hw::dss::HwStructure s = hw::dss::CeroneExampleStructure();
  hw::dss::HwData data{ex.u, ex.y, std::vector<double>(ex.y.size(), ex.noise_bound), "bench"};
  hw::dss::HwOuterSet set(s, data, horizon, std::vector<std::pair<double, double>>(8, {-10, 10}));
  const int l = set.orthant_of(hw::CeroneExample::TrueParameters());
  const auto cons = set.data_constraints(l);
  const int a1 = set.layout().a_begin;
  fmt::print("N={} n={} order={} true orthant {} ({} data inequalities)\n", samples, horizon, order, l, cons.size());
  fmt::print("{:>5} {:>8} {:>7} {:>10} {:>6} {:>18} {:>9} {:>9} {:>5} {:>12} {:>12}\n", "K", "moments", "blocks", "nnz",
             "solver", "status", "wall s", "cpu s", "it", "a1 bound", "verified");
  std::fflush(stdout);  // a run cut short by `timeout` still shows what it was doing
  for (const auto& item : SplitCommas(ks)) {
    const int K = std::min<int>(std::stoi(item), cons.size());
    hw::pop::PolyProblem p;
    p.num_vars = 8;
    p.objective = hw::Polynomial::Variable(8, a1);
    p.inequalities = set.box_constraints();
    for (auto& g : set.sign_constraints(l)) p.inequalities.push_back(g);
    // Spread the K constraints over the record.
    for (int k = 0; k < K; ++k) p.inequalities.push_back(cons[static_cast<std::size_t>(k) * cons.size() / K].g);
    const auto t_build = Clock::now();
    hw::pop::MomentRelaxation r(p, order);
    const auto bounds = hw::pop::MomentVariableBounds(p, r);
    fmt::print("# K={}: {} moments, {} blocks, {} nonzeros, built in {:.2f} s\n", K, r.lmi().c.size(), r.lmi().blocks.size(),
               r.lmi().nonzeros(), std::chrono::duration<double>(Clock::now() - t_build).count());
    std::fflush(stdout);
    for (const auto& name : solver_names) {
      std::vector<double> seconds, cpu_seconds;
      hw::sdp::SdpSummary last;
      for (int rep = 0; rep < repeats; ++rep) {
        auto solver = hw::sdp::MakeSolver(name);
        hw::sdp::SdpOptions options;
        options.verbose = verbose;
        const auto t0 = Clock::now();
        const std::clock_t c0 = std::clock();
        last = solver->Solve(options, r.lmi());
        cpu_seconds.push_back(static_cast<double>(std::clock() - c0) / CLOCKS_PER_SEC);
        seconds.push_back(std::chrono::duration<double>(Clock::now() - t0).count());
      }
      const auto v = hw::sdp::VerifyLowerBound(r.lmi(), last.X, bounds, last.lower_bound);
      const double verified = v.verified() ? set.scaling().to_original(a1, v.bound) : -INFINITY;
      fmt::print("{:>5} {:>8} {:>7} {:>10} {:>6} {:>18} {:>9.2f} {:>9.2f} {:>5} {:>12.6f} {:>12.6f}\n", K,
                 r.lmi().c.size(), r.lmi().blocks.size(), r.lmi().nonzeros(), name, hw::sdp::ToString(last.status),
                 median(seconds), median(cpu_seconds), last.iterations, set.scaling().to_original(a1, last.lower_bound), verified);
      if (!last.usable())
        fmt::print("        {}: {} (gap {:.1e}, primal infeasibility {:.1e}, dual infeasibility {:.1e})\n", name,
                   last.message, last.relative_gap, last.primal_infeasibility, last.dual_infeasibility);
      std::fflush(stdout);
    }
  }
  return 0;
}
