// Same bounds, less work: one orthant's relaxation of the paper-001 example solved (a) densely, every data row
// as its full localizing block, and (b) as the engine does it: exact row reduction, then constraint generation
// over the kept rows (linear moment constraints first, blocks when violated). Same solver; prints both bounds,
// their relative difference, times and the ratio. A timing harness, not a test.
//   setmembership_pipeline_bench [--samples 100,300] [--params a1,alpha3] [--order 2] [--solver sdpa] [--snr 31]
#include <chrono>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "core/cerone_example.hpp"
#include "dss/hw_outer_set.hpp"
#include "dss/row_reduction.hpp"
#include "pop/constraint_generation.hpp"

namespace {
using Clock = std::chrono::steady_clock;
double since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

// Where a bound comes from, in scaled units: the solver's float bound, the verified one, and the generation's check.
void PrintDetails(const char* what, const hw::pop::ConstraintGenerationResult& r) {
  fmt::print("  {}: bound {:.9f} float {:.9f} primal {:.9f} verified {} origin {} round {} unfinished {} tight {} "
             "max violation {:.2e} rounds {} status {}\n",
             what, r.bound, r.float_bound, r.primal_value, r.verification.verified(), hw::pop::ToString(r.origin),
             r.bound_round, r.bound_from_unfinished_solve, r.tight, r.max_violation, r.rounds, r.last_sdp.message);
}
}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Dense relaxation vs the engine's reduced, generated one"};
  std::vector<int> samples{100, 300};
  std::vector<std::string> params{"a1", "alpha3"};
  int order = 2, horizon = 2, seed = 1;
  double snr = 31.0;
  std::string solver_name = "sdpa";
  bool skip_dense = false, details = false;
  double violation_tolerance = hw::pop::ConstraintGenerationOptions{}.violation_tolerance;
  double gap = 1e-5;
  app.add_option("--samples", samples)->delimiter(',');
  app.add_option("--params", params)->delimiter(',');
  app.add_option("--order", order);
  app.add_option("--horizon", horizon);
  app.add_option("--seed", seed);
  app.add_option("--snr", snr);
  app.add_option("--solver", solver_name);
  app.add_flag("--skip-dense", skip_dense, "only the engine's way (for sizes the dense relaxation cannot reach)");
  app.add_option("--violation-tol", violation_tolerance, "constraint generation: relative eigenvalue tolerance");
  app.add_option("--gap", gap, "the SDP's acceptable relative duality gap");
  app.add_flag("--details", details, "a line per solve: float bound, verification correction, tight, violation");
  CLI11_PARSE(app, argc, argv);
  fmt::print("{:>5} {:>7} {:>4} {:>13} {:>9} {:>13} {:>9} {:>8} {:>9} {:>7} {:>6}\n", "N", "param", "dir", "dense bound",
             "dense s", "engine bound", "engine s", "ratio", "rel diff", "blocks", "rounds");
  for (int N : samples) {
    const auto ex = hw::SimulateCeroneExample(seed, N, snr);
    hw::dss::HwData data{ex.u, ex.y, std::vector<double>(ex.y.size(), ex.noise_bound), "bench"};
    hw::dss::HwOuterSet set(hw::dss::CeroneExampleStructure(), data, horizon,
                              std::vector<std::pair<double, double>>(8, {-10.0, 10.0}));
    const int l = set.orthant_of(hw::CeroneExample::TrueParameters());
    const auto rows = set.data_constraints(l);
    std::vector<hw::Polynomial> all, fixed = set.box_constraints();
    std::vector<int> steps;
    for (const auto& d : rows) {
      all.push_back(d.g);
      steps.push_back(d.s);
    }
    for (auto& g : set.sign_constraints(l)) fixed.push_back(g);
    for (const auto& name : params) {
      const int k = static_cast<int>(std::find(set.layout().names.begin(), set.layout().names.end(), name) -
                                     set.layout().names.begin());
      for (int dir : {-1, +1}) {
        hw::pop::PolyProblem core;
        core.num_vars = set.num_vars();
        core.objective = hw::Polynomial::Variable(set.num_vars(), k);
        core.maximize = dir > 0;
        core.inequalities = fixed;
        hw::pop::ConstraintGenerationOptions gen;
        gen.order = order;
        gen.violation_tolerance = violation_tolerance;
        gen.sdp.acceptable_gap = gap;
        gen.sdp.infeasibility_tolerance = 0.5;
        gen.sdp.retry_with_default_parameters = false;
        auto solver = hw::sdp::MakeSolver(solver_name);
        double dense_bound = NAN, dense_s = NAN;
        if (!skip_dense) {
          auto dense_problem = core;
          for (const auto& g : all) dense_problem.inequalities.push_back(g);
          const auto t0 = Clock::now();
          const auto d = hw::pop::SolveWithConstraintGeneration(gen, dense_problem, {}, {}, *solver);
          dense_s = since(t0);
          dense_bound = d.status == hw::pop::RelaxationStatus::kSolved ? set.scaling().to_original(k, d.bound) : NAN;
          if (details) PrintDetails("dense", d);
        }
        const auto t1 = Clock::now();
        const auto red = hw::dss::ReduceDataRows({}, all, steps, fixed);
        std::vector<hw::Polynomial> kept;
        for (int i : red.kept) kept.push_back(all[i]);
        const auto e = hw::pop::SolveWithConstraintGeneration(gen, core, kept, {}, *solver);
        const double engine_s = since(t1);
        const double engine_bound =
            e.status == hw::pop::RelaxationStatus::kSolved ? set.scaling().to_original(k, e.bound) : NAN;
        if (details) PrintDetails("engine", e);
        fmt::print("{:>5} {:>7} {:>4} {:>13.7f} {:>9.1f} {:>13.7f} {:>9.1f} {:>8.2f} {:>9.1e} {:>7} {:>6}\n", N, name,
                   dir < 0 ? "min" : "max", dense_bound, dense_s, engine_bound, engine_s, dense_s / engine_s,
                   std::abs(engine_bound - dense_bound) / std::max(1.0, std::abs(dense_bound)), e.working_set.size(),
                   e.rounds);
        std::fflush(stdout);
      }
    }
  }
  return 0;
}
