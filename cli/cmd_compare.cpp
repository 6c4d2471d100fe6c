// `hwbounds compare`: Monte Carlo comparison of the set-membership bounds and the two estimators on one
// scenario (docs/compare.md).
#include <fmt/format.h>

#include "cli/commands.hpp"
#include "compare/study.hpp"
#include "core/input_error.hpp"
#include "core/output_files.hpp"

namespace hw::cli {

void AddCompareCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "compare",
      "Comparison study: every method on the same plant and noise level with its own experiment, R seeded runs "
      "in parallel worker processes; writes DIR/summary.md, summary.json, runs/<study key>/jobs/*.json and plots");
  struct Opts {
    std::string scenario, out;
    std::vector<std::string> methods = {"setmembership", "brouri", "esmaeilani"}, params;
    int runs = 20, jobs = 2;
    std::uint64_t seed = 1;
    int sm_samples = 0, horizon = 0, order = 0, esm_samples = 0, esm_segments = 0, val_samples = 0, periods = 0;
    int contract_passes = -1;
    double box = 0.0;
    bool no_plots = false, quiet = false;
  };
  auto o = std::make_shared<Opts>();
  cmd->add_option("--scenario", o->scenario,
                  "built-in scenario (setmembership-example, brouri-backlash, valve) or scenario JSON file")
      ->required();
  cmd->add_option("--methods", o->methods, "comma list of setmembership, exact (the exact set D after D^ss(n)), brouri, esmaeilani (default: "
                  "setmembership, brouri, esmaeilani)")
      ->delimiter(',');
  cmd->add_option("--runs", o->runs, "Monte Carlo runs R (run r uses seed S + r)");
  cmd->add_option("--seed", o->seed, "study seed S (also the seed of the common validation record)");
  cmd->add_option("--out", o->out, "output directory (a rerun with the same settings resumes)")->required();
  cmd->add_option("--jobs", o->jobs, "worker processes (0 = one per core)")->check(CLI::NonNegativeNumber);
  cmd->add_option("--sm-samples", o->sm_samples, "override: set-membership record length N")->check(CLI::PositiveNumber)->default_str("the scenario's");
  cmd->add_option("--horizon", o->horizon, "override: set-membership horizon n")->check(CLI::PositiveNumber)->default_str("the scenario's");
  cmd->add_option("--order", o->order, "override: relaxation order delta")->check(CLI::PositiveNumber)->default_str("the scenario's");
  cmd->add_option("--contract-passes", o->contract_passes,
                  "override: set-membership cheap passes repeated in each orthant's contracted box (0..10)")
      ->check(CLI::NonNegativeNumber)
      ->default_str("the scenario's");
  cmd->add_option("--params", o->params, "override: only these intervals (no point estimate then)")
      ->delimiter(',')
      ->default_str("the scenario's");
  cmd->add_option("--box", o->box, "override: prior box half-width for every parameter")->check(CLI::PositiveNumber)->default_str("the scenario's");
  cmd->add_option("--esm-samples", o->esm_samples, "override: Esmaeilani samples per operating record")->check(CLI::PositiveNumber)->default_str("the scenario's");
  cmd->add_option("--esm-segments", o->esm_segments, "override: number of Esmaeilani operating records")->check(CLI::PositiveNumber)->default_str("the scenario's");
  cmd->add_option("--val-samples", o->val_samples, "override: validation record length")->check(CLI::PositiveNumber)->default_str("the scenario's");
  cmd->add_option("--periods", o->periods, "override: Brouri sine periods averaged (N of eq. 23)")->check(CLI::PositiveNumber)->default_str("the scenario's");
  cmd->add_flag("--no-plots", o->no_plots, "skip gnuplot");
  cmd->add_flag("--quiet", o->quiet, "no per-run progress lines");
  cmd->callback([o] {
    CheckOutputDirectory(o->out, "--out");
    compare::Scenario s = compare::LoadScenario(o->scenario);
    if (o->sm_samples > 0) s.setmembership.samples = o->sm_samples;
    if (o->horizon > 0) s.setmembership.horizon = o->horizon;
    if (o->order > 0) s.setmembership.order = o->order;
    if (o->contract_passes >= 0) s.setmembership.contract_passes = o->contract_passes;
    if (!o->params.empty()) s.setmembership.parameters = o->params;
    if (o->box > 0) {
      s.setmembership.box.clear();
      s.setmembership.box_half_width = o->box;
    }
    if (o->esm_samples > 0) s.esmaeilani.samples = o->esm_samples;
    if (o->esm_segments > 0) s.esmaeilani.segments = o->esm_segments;
    if (o->val_samples > 0) s.validation.samples = o->val_samples;
    if (o->periods > 0) s.brouri.periods = o->periods;
    std::string err;
    if (!s.IsValid(&err)) throw InputError("scenario " + s.name + " after overrides: " + err);
    compare::StudyOptions opt;
    opt.methods = o->methods;
    opt.runs = o->runs;
    opt.seed = o->seed;
    opt.out_dir = o->out;
    opt.jobs = o->jobs;
    opt.plots = !o->no_plots;
    opt.quiet = o->quiet;
    const auto r = compare::RunStudy(opt, s);
    fmt::print("{}\n", compare::SummaryMarkdown(r.summary));
    fmt::print("compare: {}; wrote {}/summary.md, summary.json, runs/, plots/\n", r.message, o->out);
    if (!r.coverage_ok)
      throw std::runtime_error("a guaranteed interval excluded the truth (coverage failure): see " + o->out +
                               "/summary.md");
  });
}

}  // namespace hw::cli
