// The lifted LP of the exact set (exact/lifted_lp.hpp) on the paper-001 example, per LP backend: time and
// iterations of a cold solve, of a child box warm-started from its parent's basis, of a bounding LP cold and
// warm-started from the emptiness LP's basis, and of a short window; medians of repeats, and the ratio of the
// backends. The box is the start box of a committed exact-set run (default: seed 1, N = 1000, 31 dB).
// A timing harness, not a test.
//   exact_lp_bench [--samples 1000] [--solvers clp,glpk] [--repeats 3] [--window 300]
//                  [--box paper_examples/results/exact_snr31_seed1/exact.json]
#include <algorithm>
#include <fstream>
#include <map>

#include <CLI/CLI.hpp>
#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "core/cerone_example.hpp"
#include "dss/hw_outer_set.hpp"
#include "exact/branch_and_bound.hpp"
#include "exact/lifted_lp.hpp"
#include "exact/lp_solver.hpp"
#include "exact/safe_bound.hpp"

namespace {

using namespace hw::exact;

struct Measure {
  std::vector<double> seconds;
  int iterations = 0;
  std::string status;
  double safe_bound = 0.0;
  double median() const {
    auto s = seconds;
    std::sort(s.begin(), s.end());
    return s[s.size() / 2];
  }
};

Measure Time(LpSolver& solver, const LpProblem& lp, const LpBasis& warm, int repeats, LpBasis* basis_out = nullptr) {
  Measure m;
  for (int r = 0; r < repeats; ++r) {
    const LpResult res = solver.Solve(lp, warm, LpSolveOptions{});
    m.seconds.push_back(res.seconds);
    m.iterations = res.iterations;
    m.status = ToString(res.status);
    m.safe_bound = res.duals.empty() ? -INFINITY : SafeLowerBound(lp, res.duals);
    if (basis_out) *basis_out = res.basis;
  }
  return m;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Lifted-LP solve times of the exact set, per LP backend"};
  int samples = 1000, repeats = 3, window = 300, seed = 1;
  double snr = 31.0;
  std::vector<std::string> solvers{"clp", "glpk"};
  std::string box_file = std::string(HW_SOURCE_DIR) + "/paper_examples/results/exact_snr31_seed1/exact.json";
  app.add_option("--samples", samples);
  app.add_option("--seed", seed);
  app.add_option("--snr", snr);
  app.add_option("--solvers", solvers)->delimiter(',');
  app.add_option("--repeats", repeats)->check(CLI::PositiveNumber);
  app.add_option("--window", window, "samples of the short window");
  app.add_option("--box", box_file, "an exact.json whose start_box is the box");
  CLI11_PARSE(app, argc, argv);
  std::ifstream in(box_file);
  const ParamBox box = BoxFromJson(nlohmann::json::parse(in).at("start_box"));
  const auto ex = hw::SimulateCeroneExample(seed, samples, snr);
  hw::dss::HwData data{ex.u, ex.y, std::vector<double>(ex.y.size(), ex.noise_bound), "bench"};
  const LiftedData lifted = MakeLiftedData(hw::dss::CeroneExampleStructure(), data);
  const int a1 = lifted.layout.a_begin, alpha3 = lifted.layout.alpha_begin + 1;

  LiftedLp parent = BuildLiftedLp(lifted, box, WholeRecord(lifted), LiftedForm::kFeasibility);
  parent.SetSlackObjective();
  LiftedLp child = BuildLiftedLp(lifted, HalveBox(box, a1).first, WholeRecord(lifted), LiftedForm::kFeasibility);
  child.SetSlackObjective();
  LiftedLp bounding = BuildLiftedLp(lifted, box, WholeRecord(lifted), LiftedForm::kBounding);
  std::vector<double> weights(lifted.layout.count(), 0.0);
  weights[alpha3] = -1.0;  // max alpha3
  bounding.SetParameterObjective(weights);
  LiftedLp shortw = BuildLiftedLp(lifted, box, {0, std::min(window, samples)}, LiftedForm::kFeasibility);
  shortw.SetSlackObjective();
  fmt::print("N {} (seed {}, {} dB): LP {} rows x {} cols, {} nonzeros; box from {}; median of {}\n", samples, seed, snr,
             parent.lp.num_rows(), parent.lp.num_cols(), parent.lp.entries.size(), box_file, repeats);
  fmt::print("{:<6} {:<34} {:>9} {:>7} {:>11} {:>12}\n", "solver", "LP", "median s", "iters", "status", "safe bound");
  std::map<std::string, std::map<std::string, double>> medians;
  for (const auto& name : solvers) {
    auto solver = MakeLpSolver(name);
    LpBasis parent_basis, none;
    auto row = [&](const std::string& what, const Measure& m) {
      fmt::print("{:<6} {:<34} {:>9.3f} {:>7} {:>11} {:>12.4g}\n", name, what, m.median(), m.iterations, m.status,
                 m.safe_bound);
      medians[what][name] = m.median();
    };
    row("emptiness, cold", Time(*solver, parent.lp, none, repeats, &parent_basis));
    row("emptiness, child warm from parent", Time(*solver, child.lp, parent_basis, repeats));
    row("bound max alpha3, cold", Time(*solver, bounding.lp, none, repeats));
    row("bound max alpha3, warm", Time(*solver, bounding.lp, parent_basis, repeats));
    row(fmt::format("emptiness, {} samples, cold", std::min(window, samples)), Time(*solver, shortw.lp, none, repeats));
  }
  if (solvers.size() == 2) {
    fmt::print("ratio {}/{} of medians:\n", solvers[1], solvers[0]);
    for (const auto& [what, by] : medians)
      fmt::print("  {:<34} {:.2f}\n", what, by.at(solvers[1]) / by.at(solvers[0]));
  }
  return 0;
}
