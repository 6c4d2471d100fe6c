// One set-membership job (paper-001 example, one orthant, min or max of one parameter) solved by constraint
// generation, round by round: working-set size, SDP time and iterations, status, bound, and the time spent
// outside the solver (building the LMI, checking omitted constraints). A timing harness, not a test.
//   setmembership_job_bench [--samples N] [--horizon n] [--order d] [--param a1] [--max] [--solver sdpa]
//                           [--add-per-round K] [--box LO,HI] [--snr 31]
#include <chrono>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "core/cerone_example.hpp"
#include "dss/hw_outer_set.hpp"
#include "pop/constraint_generation.hpp"
#include "pop/moment_lp.hpp"
#include "sdp/sdp_solver.hpp"

namespace {
using Clock = std::chrono::steady_clock;
double since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }
}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"One set-membership relaxation job, round by round"};
  int samples = 1000, horizon = 2, order = 2, add = 20, orthant = -1;
  std::string param = "a1", solver_name = "sdpa";
  bool maximize = false, verify = false, no_linear_rows = false;
  int contract_rounds = 0, block_order_cap = -1, start_order = 0;
  double gap = 1e-7, feasibility = 1e-7;
  bool keep_prior_box = false;
  double box = 10.0, snr_db = 31.0;
  std::vector<double> box_list;
  app.add_option("--samples", samples);
  app.add_option("--snr", snr_db, "SNR_w of the realisation in dB (sets the noise bound)");
  app.add_option("--horizon", horizon);
  app.add_option("--order", order);
  app.add_option("--param", param);
  app.add_flag("--max", maximize);
  app.add_option("--solver", solver_name);
  app.add_option("--add-per-round", add);
  app.add_option("--orthant", orthant, "default: the true parameters' orthant");
  app.add_option("--box", box, "prior box [-box, box] for every parameter");
  app.add_option("--box-list", box_list, "lo1,hi1,...,lo8,hi8: a box per parameter (overrides --box)")
      ->delimiter(',');
  app.add_flag("--verify", verify);
  app.add_flag("--no-linear-rows", no_linear_rows, "candidates without a block are left out (not scalar rows)");
  app.add_option("--gap", gap, "the solver's relative gap tolerance");
  app.add_option("--feasibility", feasibility, "the solver's relative feasibility tolerance");
  app.add_option("--start-order", start_order,
                 "first solve the job at this (lower) order and start from the rows it found active, as the engine's "
                 "full pass starts from its cheap pass");
  app.add_option("--block-order-cap", block_order_cap, "data-row blocks of order <= this (-1: full order)");
  app.add_flag("--keep-prior-box", keep_prior_box,
               "scale variables by --box-list but constrain them by the prior box --box only (an affine change of "
               "variables: the same relaxation, other conditioning)");
  app.add_option("--lp-contract", contract_rounds, "rounds of LP box contraction in the orthant before the job");
  CLI11_PARSE(app, argc, argv);

  const auto ex = hw::SimulateCeroneExample(1, samples, snr_db);
  hw::dss::HwData data{ex.u, ex.y, std::vector<double>(ex.y.size(), ex.noise_bound), "bench"};
  std::vector<std::pair<double, double>> boxes(8, {-box, box});
  if (box_list.size() == 16)
    for (int i = 0; i < 8; ++i) boxes[i] = {box_list[2 * i], box_list[2 * i + 1]};
  const int l = orthant >= 0 ? orthant
                             : hw::dss::HwOuterSet(hw::dss::CeroneExampleStructure(), data, horizon, boxes)
                                   .orthant_of(hw::CeroneExample::TrueParameters());
  for (int round = 1; round <= contract_rounds; ++round) {
    hw::dss::HwOuterSet s(hw::dss::CeroneExampleStructure(), data, horizon, boxes);
    std::vector<hw::Polynomial> cons = s.sign_constraints(l);
    for (auto& c : s.data_constraints(l)) cons.push_back(c.g);
    const auto tc = Clock::now();
    auto lp_solver = hw::sdp::MakeSolver(solver_name);
    fmt::print("LP contraction round {}:", round);
    for (int i = 0; i < 8; ++i) {
      const auto lo = hw::pop::LinearProgramBound(cons, 8, i, -1, {}, *lp_solver);
      const auto hi = hw::pop::LinearProgramBound(cons, 8, i, +1, {}, *lp_solver);
      const double nlo = lo.status == lo.kBounded ? s.scaling().to_original(i, lo.bound) : boxes[i].first;
      const double nhi = hi.status == hi.kBounded ? s.scaling().to_original(i, hi.bound) : boxes[i].second;
      boxes[i] = {std::max(boxes[i].first, nlo), std::min(boxes[i].second, nhi)};
      fmt::print(" {} [{:.4f}, {:.4f}]", s.layout().names[i], boxes[i].first, boxes[i].second);
    }
    fmt::print("  ({:.2f} s)\n", since(tc));
  }
  hw::dss::HwOuterSet set(hw::dss::CeroneExampleStructure(), data, horizon, boxes);
  const auto& names = set.layout().names;
  const int k = static_cast<int>(std::find(names.begin(), names.end(), param) - names.begin());
  if (k >= set.num_vars()) {
    fmt::print(stderr, "unknown parameter {}\n", param);
    return 2;
  }
  std::vector<hw::Polynomial> candidates;
  for (auto& c : set.data_constraints(l)) candidates.push_back(std::move(c.g));
  hw::pop::PolyProblem core;
  core.num_vars = set.num_vars();
  core.objective = hw::Polynomial::Variable(core.num_vars, k);
  core.maximize = maximize;
  core.inequalities = set.box_constraints();
  if (keep_prior_box) {
    core.inequalities.clear();
    const auto sub = set.scaling().substitution();
    for (int i = 0; i < core.num_vars; ++i) {
      hw::Polynomial g = (sub[i] + hw::Polynomial::Constant(core.num_vars, box)) *
                         (hw::Polynomial::Constant(core.num_vars, box) - sub[i]);
      double big = 0.0;
      for (const auto& [e, c] : g.terms()) big = std::max(big, std::abs(c));
      core.inequalities.push_back(g * (1.0 / big));
    }
  }
  for (auto& g : set.sign_constraints(l)) core.inequalities.push_back(g);
  hw::pop::ConstraintGenerationOptions gen;
  gen.order = order;
  gen.add_per_round = add;
  gen.verify.enabled = verify;
  gen.sdp.acceptable_gap = 1e-5;
  gen.sdp.infeasibility_tolerance = 0.5;
  gen.sdp.gap_tolerance = gap;
  gen.sdp.feasibility_tolerance = feasibility;
  gen.block_order_cap = block_order_cap;
  gen.linear_rows_first = !no_linear_rows;
  auto solver = hw::sdp::MakeSolver(solver_name);
  fmt::print("N={} n={} order={} orthant {} {} {} ({} candidates), solver {}\n", samples, horizon, order, l,
             maximize ? "max" : "min", param, candidates.size(), solver_name);
  std::vector<int> initial;
  if (start_order > 0) {
    auto cheap = gen;
    cheap.order = start_order;
    const auto tc = Clock::now();
    const auto c = hw::pop::SolveWithConstraintGeneration(cheap, core, candidates, {}, *solver);
    initial = c.active_set.empty() ? c.working_set : c.active_set;
    fmt::print("order {} first: bound {:.8f} in {} rounds, {:.2f} s; {} active rows start the order-{} job\n",
               start_order, c.bound, c.rounds, since(tc), initial.size(), order);
  }
  fmt::print("{:>5} {:>5} {:>9} {:>9}\n", "round", "K", "elapsed", "");
  const auto t0 = Clock::now();
  int round = 0;
  const auto r = hw::pop::SolveWithConstraintGeneration(
      gen, core, candidates, initial, *solver, [&](const hw::pop::GenerationRound& r) {
        fmt::print("{:>5} {:>5} {:>9.2f}  {} bound {:.8f}\n", ++round, r.blocks, since(t0), r.status, r.bound);
        std::fflush(stdout);
      });
  fmt::print("status {} bound {:.6f} (original units {:.6f}) tight {} rounds {} iterations {} solver {:.2f} s of "
             "{:.2f} s wall\n{}\nlast SDP: {}\n",
             hw::pop::ToString(r.status), r.bound, set.scaling().to_original(k, r.bound), r.tight, r.rounds,
             r.sdp_iterations, r.solve_seconds, since(t0), r.message, r.last_sdp.message);
  return 0;
}
