// Cost of verified bounds (sdp/verified_bound.hpp) relative to the SDP solves they verify, on set-membership
// relaxations of the paper-001 example (true orthant, min and max of every parameter, K data inequalities in the
// LMI), plus infeasibility certificates of other orthants. Prints per-problem times, medians and the ratio
// verification / solve, and the corrections. A timing harness, not a test.
//   verify_bench [--samples N] [--horizon n] [--order d] [--k K] [--solver sdpa] [--params a1,b1] [--empty E]
#include <algorithm>
#include <chrono>
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
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}
double since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }
}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Verification cost vs SDP solve time on set-membership relaxations"};
  int samples = 300, horizon = 2, order = 2, K = 40, empty_count = 4;
  std::string solver_name = "sdpa", params_text = "a1,alpha3,b1";
  app.add_option("--samples", samples);
  app.add_option("--horizon", horizon);
  app.add_option("--order", order);
  app.add_option("--k", K, "data inequalities in each LMI (spread over the record)");
  app.add_option("--solver", solver_name);
  app.add_option("--params", params_text, "parameters whose min and max are solved");
  app.add_option("--empty", empty_count, "orthants whose (infeasible) relaxation is solved to time certificates");
  CLI11_PARSE(app, argc, argv);
  const auto ex = hw::SimulateCeroneExample(1, samples);
  hw::dss::HwData data{ex.u, ex.y, std::vector<double>(ex.y.size(), ex.noise_bound), "bench"};
  hw::dss::HwOuterSet set(hw::dss::CeroneExampleStructure(), data, horizon,
                            std::vector<std::pair<double, double>>(8, {-10, 10}));
  const int n = set.num_vars();
  const int truth_orthant = set.orthant_of(hw::CeroneExample::TrueParameters());
  auto solver = hw::sdp::MakeSolver(solver_name);
  hw::sdp::SdpOptions sdp_options;
  sdp_options.keep_dual_matrix = true;
  sdp_options.acceptable_gap = 1e-5;  // as the set-membership engine runs them

  auto problem_for = [&](int l, int param, bool maximize) {
    hw::pop::PolyProblem p;
    p.num_vars = n;
    p.objective = hw::Polynomial::Variable(n, param);
    p.maximize = maximize;
    p.inequalities = set.box_constraints();
    for (auto& g : set.sign_constraints(l)) p.inequalities.push_back(g);
    const auto cons = set.data_constraints(l);
    const int k_used = std::min<int>(K, cons.size());
    for (int k = 0; k < k_used; ++k) p.inequalities.push_back(cons[static_cast<std::size_t>(k) * cons.size() / k_used].g);
    return p;
  };

  fmt::print("N={} n={} order={} K={} solver {}; true orthant {}\n", samples, horizon, order, K, solver_name,
             truth_orthant);
  fmt::print("{:<12} {:>8} {:>7} {:>9} {:>10} {:>10} {:>8} {:>12} {:>10} {:>10}\n", "objective", "moments", "blocks",
             "solve s", "verify s", "+resolve s", "ratio", "correction", "min eig", "status");
  std::vector<double> solve_t, verify_t, full_t, corrections;
  int unverified = 0;
  std::stringstream ps(params_text);
  std::string name;
  while (std::getline(ps, name, ',')) {
    const auto& names = set.layout().names;
    const int param = static_cast<int>(std::find(names.begin(), names.end(), name) - names.begin());
    if (param >= n) {
      fmt::print(stderr, "no parameter '{}'\n", name);
      return 2;
    }
    for (bool maximize : {false, true}) {
      const auto p = problem_for(truth_orthant, param, maximize);
      hw::pop::MomentRelaxation r(p, order);
      const auto t0 = Clock::now();
      const auto s = solver->Solve(sdp_options, r.lmi());
      const double ts = since(t0);
      if (s.status != hw::sdp::SdpStatus::kOptimal) {
        fmt::print("{:<12} solve ended {}\n", name + (maximize ? " max" : " min"), hw::sdp::ToString(s.status));
        continue;
      }
      const auto bounds = hw::pop::MomentVariableBounds(p, r);
      const auto t1 = Clock::now();
      const auto v = hw::sdp::VerifyLowerBound(r.lmi(), s.X, bounds, s.lower_bound);  // the verification alone
      const double tv = since(t1);
      const auto w = hw::sdp::VerifyOptimalSolve({}, sdp_options, r.lmi(), bounds, s, *solver);  // with re-solves
      solve_t.push_back(ts);
      verify_t.push_back(tv);
      full_t.push_back(w.seconds);
      if (w.verified()) corrections.push_back(w.correction);
      else ++unverified;
      fmt::print("{:<12} {:>8} {:>7} {:>9.3f} {:>10.4f} {:>10.3f} {:>8.4f} {:>12.2e} {:>10.2e} {:>10}\n",
                 name + (maximize ? " max" : " min"), r.lmi().num_vars(), r.lmi().blocks.size(), ts, tv,
                 w.resolve_seconds, tv / ts, w.correction, v.min_eigenvalue,
                 hw::sdp::ToString(w.status) + (w.resolves ? fmt::format(" ({}rs)", w.resolves) : ""));
    }
  }
  // Infeasibility certificates: other orthants, min of the first parameter.
  std::vector<double> inf_solve, inf_verify;
  int certificates = 0, verified_certificates = 0;
  for (int l = 0; l < set.num_orthants() && certificates < empty_count; ++l) {
    if (l == truth_orthant) continue;
    const auto p = problem_for(l, 0, false);
    hw::pop::MomentRelaxation r(p, order);
    const auto t0 = Clock::now();
    const auto s = solver->Solve(sdp_options, r.lmi());
    const double ts = since(t0);
    if (s.status != hw::sdp::SdpStatus::kInfeasible) continue;
    ++certificates;
    const auto t1 = Clock::now();
    const auto v = hw::sdp::VerifyInfeasibility(r.lmi(), s.X, hw::pop::MomentVariableBounds(p, r));
    const double tv = since(t1);
    inf_solve.push_back(ts);
    inf_verify.push_back(tv);
    verified_certificates += v.verified();
    fmt::print("orthant {:>3} infeasible: solve {:.3f} s, verify {:.4f} s, {}\n", l, ts, tv, v.message);
  }
  const double ms = median(solve_t), mv = median(verify_t), mf = median(full_t);
  fmt::print("\nbounds: {} solves, {} unverified; median solve {:.3f} s, median verification {:.4f} s (ratio {:.4f}), "
             "median verification incl. re-solves {:.4f} s (ratio {:.4f}); median correction {:.2e}, max {:.2e}\n",
             solve_t.size(), unverified, ms, mv, ms > 0 ? mv / ms : 0.0, mf, ms > 0 ? mf / ms : 0.0, median(corrections),
             corrections.empty() ? 0.0 : *std::max_element(corrections.begin(), corrections.end()));
  fmt::print("certificates: {} of {} verified; median solve {:.3f} s, median verification {:.4f} s (ratio {:.4f})\n",
             verified_certificates, certificates, median(inf_solve), median(inf_verify),
             median(inf_solve) > 0 ? median(inf_verify) / median(inf_solve) : 0.0);
  return 0;
}
