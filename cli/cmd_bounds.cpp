// `hwbounds bounds`: guaranteed parameter intervals of a Hammerstein–Wiener model from a recording.
#include <algorithm>
#include <cmath>
#include <optional>
#include <sstream>
#include <thread>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "cli/bounds_plot.hpp"
#include "cli/commands.hpp"
#include "cli/progress_display.hpp"
#include "core/csv_table.hpp"
#include "core/output_files.hpp"
#include "core/recording.hpp"
#include "exact/exact_bounds.hpp"
#include "exact/exact_report.hpp"
#include "exact/two_stage.hpp"
#include "dss/bounds_report.hpp"
#include "dss/box_split.hpp"
#include "dss/set_membership.hpp"
#include "sdp/sdp_solver.hpp"

namespace hw::cli {
namespace {

// "--box -10,10" (all parameters) or "--box a1=0,3 --box b1=-5,5" (named); later entries win. The text's syntax
// is checked here, the values by the library's ValidBoxEntry (the Python module's box gets the same message).
std::vector<std::pair<double, double>> parse_box(const std::vector<std::string>& specs,
                                                 const std::vector<std::string>& names) {
  std::vector<std::pair<double, double>> box(names.size(), {-10.0, 10.0});
  for (const auto& spec : specs) {
    std::string target, range = spec;
    if (auto eq = spec.find('='); eq != std::string::npos) {
      target = spec.substr(0, eq);
      range = spec.substr(eq + 1);
    }
    double lo = 0, hi = 0;
    char comma = 0;
    std::istringstream in(range);
    if (!(in >> lo >> comma >> hi) || comma != ',' || !(in >> std::ws).eof())
      throw InputError(fmt::format("--box '{}': expected LO,HI (every parameter) or NAME=LO,HI", spec));
    RequireOption(fmt::format("--box '{}'", spec),
                  [&](std::string* e) { return dss::ValidBoxEntry(target, lo, hi, names, e); });
    for (std::size_t i = 0; i < names.size(); ++i)
      if (target.empty() || names[i] == target) box[i] = {lo, hi};
  }
  return box;
}

std::vector<double> parse_list(const std::string& text, const std::string& what) {
  std::vector<double> v;
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, ',')) {
    std::size_t used = 0;
    try {
      v.push_back(std::stod(item, &used));
    } catch (...) {
      used = 0;
    }
    if (used == 0 || used != item.size()) throw InputError(fmt::format("{}: '{}' is not a number", what, item));
  }
  return v;
}

// "--split gamma2=0" or "--split a1=1.7,1.8 --split b1=0": the prior box is cut at these values (one entry per
// parameter). The text's syntax is checked here, the values against the box by the library's ValidBoxCuts.
std::vector<dss::BoxCut> parse_split(const std::vector<std::string>& specs) {
  std::vector<dss::BoxCut> cuts;
  for (const auto& spec : specs) {
    const auto eq = spec.find('=');
    if (eq == std::string::npos || eq == 0 || eq + 1 == spec.size())
      throw InputError(fmt::format("--split '{}': expected NAME=VALUE[,VALUE...], e.g. --split gamma2=0", spec));
    cuts.push_back({spec.substr(0, eq), parse_list(spec.substr(eq + 1), fmt::format("--split '{}'", spec))});
  }
  return cuts;
}

// Exit status of a run whose data prove that no parameter in the prior box fits (docs/input_output.md, `bounds --help`).
constexpr int kExitInvalidated = 3;

struct BoundsCliOptions {
  std::string data, u_col = "u", y_col = "y", noise_col, input_basis = "poly:3", output_basis = "poly:3";
  std::string solver = "auto", json_out, plot_out, run_dir, truth, executor = "fork";
  std::vector<std::string> box, params, split;
  double noise_bound = 0.0;
  int na = 2, nb = 2, horizon = 2, order = 0, threads = 0;
  bool order_given = false, noise_bound_given = false;  // --order, --noise-bound on the command line
  bool proper = false, no_cheap = false, no_edge_witnesses = false, no_moment_witnesses = false, no_full_pass_contraction = false, solver_retry = false, quiet = false, verbose = false, verify = false, no_verify = false;
  int contraction_passes = 0;
  int stopped_short_refinements = dss::BoundsOptions{}.stopped_short_refinements;
  int endpoint_refinements = 0;
  int row_block_order = -1;
  int auto_split = 0;
  std::string set = "dss";  // which feasible set the intervals bound: dss (D^ss(n)) or exact (D, after D^ss(n))
  int lp_budget = exact::ObjectiveSearchOptions{}.lp_budget;
  int sweeps = exact::ExactBoundsOptions{}.sweeps;
  double target_ratio = exact::ExactBoundsOptions{}.target_ratio;
  std::string lp_solver = exact::ExactBoundsOptions{}.lp_solver;
};

// What the bounds of the exact set D need besides the D^ss(n) run: its start box is that run's result.
exact::ExactBoundsOptions MakeExactOptions(const BoundsCliOptions& o, const dss::BoundsOptions& dss) {
  if (o.lp_budget < 1)
    throw InputError(fmt::format("--lp-budget {}: LPs per endpoint refinement must be at least 1", o.lp_budget));
  if (o.sweeps < 1 || o.sweeps > 5) throw InputError(fmt::format("--sweeps {}: expected 1..5", o.sweeps));
  if (!(o.target_ratio >= 1.0))
    throw InputError(fmt::format("--target-ratio {}: expected a ratio of widths >= 1, e.g. 1.25", o.target_ratio));
  exact::ExactBoundsOptions options;
  options.executor = dss.executor;
  options.run_dir = o.run_dir;
  options.parameters = o.params;
  options.search.lp_budget = o.lp_budget;
  options.sweeps = o.sweeps;
  options.target_ratio = o.target_ratio;
  options.lp_solver = o.lp_solver;
  std::string error;
  if (!options.IsValid(&error)) throw InputError(error);
  return options;
}

ExactPlotIntervals PlotIntervalsOf(const exact::ExactBoundsSummary& s) {
  ExactPlotIntervals p;
  for (const auto& iv : s.intervals) {
    p.outer.emplace_back(iv.lower.value, iv.upper.value);
    p.inner.push_back(iv.inner.value_or(std::pair<double, double>{NAN, NAN}));
  }
  return p;
}

dss::HwData ReadData(const BoundsCliOptions& o) {
  std::vector<std::string> columns = {o.u_col, o.y_col};
  if (!o.noise_col.empty()) columns.push_back(o.noise_col);
  // A time column (t=VAR, or a CSV column t) is checked and not used: the model runs on the sample index.
  const CsvTable table = read_recording(o.data, columns, {"t"});
  dss::HwData data;
  data.source = o.data;
  data.lines = table.lines;
  data.u = table.column(o.u_col);
  data.y = table.column(o.y_col);
  if (!o.noise_col.empty()) {
    data.noise_bound = table.column(o.noise_col);
  } else {
    if (!o.noise_bound_given) throw InputError("give the noise bound: --noise-bound VALUE or --noise-col COLUMN");
    RequireOption("--noise-bound", [&](std::string* e) { return dss::ValidNoiseBound(o.noise_bound, e); });
    data.noise_bound.assign(data.y.size(), o.noise_bound);
  }
  return data;
}

dss::HwStructure ReadStructure(const BoundsCliOptions& o) {
  dss::HwStructure structure;
  structure.input_basis = dss::parse_basis(o.input_basis);
  structure.output_basis = dss::parse_basis(o.output_basis);
  structure.na = o.na;
  structure.nb = o.nb;
  structure.strictly_proper = !o.proper;
  std::string error;
  if (!structure.IsValid(&error)) throw InputError(error);
  return structure;
}

// The option values the library checks (the Python module's checks, with the same messages), before any work.
void CheckBoundsOptions(const BoundsCliOptions& o) {
  dss::BoundsSettings settings;
  settings.horizon = o.horizon;
  if (o.order_given) settings.order = o.order;
  settings.solver = o.solver;
  settings.threads = o.threads;
  settings.executor = o.executor;
  settings.contraction_passes = o.contraction_passes;
  settings.row_block_order = o.row_block_order;
  settings.stopped_short_refinements = o.stopped_short_refinements;
  settings.endpoint_refinements = o.endpoint_refinements;
  settings.auto_split_rounds = o.auto_split;
  for (const auto& check : dss::SettingChecks(settings)) RequireOption(check.cli_option, check.valid);
}

// "csdp", or for --solver auto the backend of each order, e.g. "auto (csdp at order 2, dsdp at order 3)".
std::string SolverText(const dss::BoundsOptions& options) {
  if (options.solver != "auto") return options.solver;
  std::vector<std::string> parts;
  for (int d = std::min(options.order, 2); d <= options.order; ++d)  // the cheap pass runs at order 2 at most
    parts.push_back(fmt::format("{} at order {}",
                                dss::SolverForOrder("auto", d, options.generation.block_order_cap), d));
  return fmt::format("auto ({})", fmt::join(parts, ", "));
}

dss::BoundsOptions MakeBoundsOptions(const BoundsCliOptions& o) {
  dss::BoundsOptions options;
  options.order = o.order_given ? o.order : dss::MinimalOrder(o.horizon);
  options.solver = o.solver;
  options.threads = o.threads;
  options.executor = sdp::MakeExecutor(o.executor, o.threads);
  options.run_dir = o.run_dir;
  options.cheap_pass = !o.no_cheap;
  options.edge_witness.enabled = !o.no_edge_witnesses;
  options.moment_witnesses = !o.no_moment_witnesses;
  options.contract_before_full_pass = !o.no_full_pass_contraction;
  options.generation.retry_undecided_rounds = o.solver_retry;
  options.contraction_passes = o.contraction_passes;
  options.stopped_short_refinements = o.stopped_short_refinements;
  options.endpoint_refinements = o.endpoint_refinements;
  options.generation.block_order_cap = o.row_block_order;
  options.parameters = o.params;
  options.generation.verify.enabled = !o.no_verify;
  if (o.verbose)  // one line per constraint-generation round, printed by the process that runs the job
    options.round_log = [](const std::string& line) { fmt::print(stderr, "  {}\n", line); };
  std::string error;
  if (!options.IsValid(&error)) throw InputError(error);
  return options;
}

// The result JSON; an invalidated model has "invalidated": true and null interval values.
nlohmann::json ResultJson(const dss::BoundsSummary& summary, const BoundsCliOptions& o, const dss::HwOuterSet& set,
                          const std::vector<double>& truth, bool covered) {
  auto j = summary.to_json();  // "invalidated", the verdict, null intervals and each orthant's certificate
  j["data"] = o.data;
  j["data_warnings"] = set.warnings();
  j["structure"] = {{"na", o.na}, {"nb", o.nb}, {"proper", o.proper}, {"input_basis", o.input_basis},
                    {"output_basis", o.output_basis}};
  if (!truth.empty() && !summary.invalidated()) {
    j["truth"] = truth;
    j["truth_covered"] = covered;
  }
  return j;
}

}  // namespace

void AddBoundsCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand("bounds", "Guaranteed parameter intervals (set-membership, paper 001) from a recording");
  cmd->footer(fmt::format(
      "Exit status: 0 intervals computed; {} model invalidated (every sign orthant proven empty: no parameter in the "
      "prior box explains the data within the noise bound; the JSON has \"invalidated\": true and null intervals); "
      "2 bad input; 1 other failure.",
      kExitInvalidated));
  auto o = std::make_shared<BoundsCliOptions>();
  cmd->add_option("--data", o->data, "recording: CSV with a header, or FILE.mat:u=VAR,y=VAR[,t=VAR] (docs/recordings.md)")
      ->required();
  cmd->add_option("--u-col", o->u_col, "input column");
  cmd->add_option("--y-col", o->y_col, "output column");
  // --noise-bound, --horizon, --order, --solver, --threads, --executor, --contract-passes: checked in the
  // callback by the library's checks (CheckBoundsOptions), which give the Python module's messages.
  auto* noise_bound = cmd->add_option("--noise-bound", o->noise_bound, "constant bound |eta_t| <= value (> 0)")
                          ->default_str("");
  auto* noise_col =
      cmd->add_option("--noise-col", o->noise_col, "column with a per-sample noise bound (instead of --noise-bound)");
  noise_bound->excludes(noise_col);
  // --na, --nb: checked by HwStructure::IsValid (the same message as the Python module's).
  cmd->add_option("--na", o->na, "denominator order");
  cmd->add_option("--nb", o->nb, "numerator order (b_0..b_nb, b_0 = 0 unless --proper)");
  cmd->add_flag("--proper", o->proper, "estimate b_0 too (proper, not strictly proper)");
  cmd->add_option("--input-basis", o->input_basis, "psi basis: poly:K or a list like 'w,w^3,tanh'");
  cmd->add_option("--output-basis", o->output_basis, "phi basis of the inverse output map");
  cmd->add_option("--horizon", o->horizon, "dynamic horizon n, 1..20");
  auto* order = cmd->add_option("--order", o->order, "relaxation order delta, from the minimal order ceil((n+1)/2) to 20")
                    ->default_str("minimal");
  cmd->add_option("--box", o->box, "prior box: LO,HI for all parameters or NAME=LO,HI")->default_str("-10,10");
  cmd->add_option("--split", o->split,
                  "cut the prior box at these values of one parameter, NAME=VALUE[,VALUE...] (repeat for more "
                  "parameters): each piece is bounded on its own and the intervals are the hull over the pieces, "
                  "often tighter (docs/cerone_tables.md, \"The relaxation gap at δ = 3\")");
  cmd->add_option("--auto-split", o->auto_split,
                  "after the run, up to this many rounds (0..5): shrink the box to the verified intervals, cut off "
                  "the largest part of an interval no certified feasible point reaches (from 10% of its width) just "
                  "beyond that point, and bound again over the pieces (docs/setmembership.md, \"Box split\")");
  cmd->add_option("--solver", o->solver,
                  fmt::format("SDP backend: auto (CSDP, measured fastest at orders 2 and 3; docs/sdp.md), {}",
                              fmt::join(sdp::AvailableSolvers(), ", ")));
  cmd->add_option("--threads", o->threads, "parallel SDP jobs on this machine (worker processes; 0 = one per core)");
  cmd->add_option("--executor", o->executor,
                  "where SDP jobs run: fork (local worker processes), inprocess, or mpi (under mpirun: rank 0 "
                  "coordinates, the other ranks solve)");
  cmd->add_option("--run-dir", o->run_dir, "keep finished SDP results here; a rerun solves only the rest");
  cmd->add_flag("--no-cheap-pass", o->no_cheap, "solve every orthant at full order (no minimal-order screening)");
  cmd->add_flag("--no-edge-witnesses", o->no_edge_witnesses,
                "solve every endpoint by SDP, also those a feasible point at the prior box edge settles");
  cmd->add_flag("--no-moment-witnesses", o->no_moment_witnesses,
                "skip the local searches from the relaxations' first moments (they only widen the \"feasible "
                "points reach\" ranges)");
  cmd->add_option("--row-block-order", o->row_block_order,
                  "localizing order of the data rows' blocks at most (-1: full order; 1 at order 3: 9x9 blocks, a "
                  "mixed relaxation between orders 2 and 3, valid and cheaper)");
  cmd->add_flag("--solver-retry", o->solver_retry,
                "solve a constraint-generation round the backend leaves undecided (partial success, pFEAS) again with "
                "the other backend before taking its verified last iterate (off: measured to cost time, not "
                "tightness, docs/setmembership_scale.md)");
  cmd->add_flag("--no-full-pass-contraction", o->no_full_pass_contraction,
                "run the order-delta jobs in the prior box, not in each orthant's box contracted to its cheap-order "
                "bounds");
  cmd->add_option("--contract-passes", o->contraction_passes,
                  "cheap passes repeated in each orthant's contracted box, 0..10 (0 = no box contraction)");
  cmd->add_option("--stopped-short-refinements", o->stopped_short_refinements,
                  "times an endpoint resting on a solve that stopped short (partial success, pFEAS) is solved again "
                  "in its orthant's box contracted to the verified bounds (0 = never)");
  cmd->add_option("--endpoint-refinements", o->endpoint_refinements,
                  "times every endpoint no certified feasible point reaches is solved again at full order in its "
                  "orthant's box contracted to the full pass's verified bounds, 0..10 (0 = never; one full-order job "
                  "per endpoint)");
  auto* verify = cmd->add_flag("--verify", o->verify,
                               "verify every bound and emptiness certificate rigorously in interval arithmetic "
                               "(the default)");
  cmd->add_flag("--no-verify", o->no_verify, "skip the verification: endpoints are the solvers' floating-point bounds")
      ->excludes(verify);
  cmd->add_option("--params", o->params, "only these intervals (names such as a1 b1)")->delimiter(',')->default_str("all");
  cmd->add_option("--truth", o->truth, "comma list of true parameters, to report coverage (simulation studies)");
  cmd->add_option("--set", o->set,
                  "which feasible set to bound: dss (D^ss(n) of paper 001, sign orthants and moment relaxations) or "
                  "exact (the exact set D, one noise sequence for the whole record, bounded by lifted LPs and branch "
                  "and bound inside the D^ss(n) box; 3-2000 times narrower; docs/exact_set.md). exact assumes the "
                  "inverse output map increases on the data range")
      ->check(CLI::IsMember({"dss", "exact"}));
  cmd->add_option("--lp-budget", o->lp_budget, "--set exact: LPs per endpoint refinement (>= 1)");
  cmd->add_option("--sweeps", o->sweeps, "--set exact: bounding sweeps at most, each in the box the previous proved; they stop once every "
                  "interval is within --target-ratio times its inner hull (1..5)");
  cmd->add_option("--target-ratio", o->target_ratio,
                  "--set exact: an endpoint's refinement stops once its interval would be at most this many times as wide "
                  "as the inner hull (>= 1; 1.25 by default; smaller costs more LPs)");
  cmd->add_option("--lp-solver", o->lp_solver, "--set exact: the LP backend, clp, glpk, ipm or ipm-only (certificates do not depend on it)")
      ->check(CLI::IsMember(exact::AvailableLpSolvers()));
  cmd->add_option("--json", o->json_out, "write the result as JSON");
  cmd->add_option("--plot", o->plot_out,
                  "draw the intervals as a PNG (gnuplot): each in its prior box and stretched to its own width, with "
                  "the certified feasible points and --truth");
  auto* quiet = cmd->add_flag("--quiet", o->quiet, "no progress lines");
  cmd->add_flag("--verbose", o->verbose,
                "also one line per constraint-generation round of every job (working set, solver status, bound so "
                "far), and progress as plain lines")
      ->excludes(quiet);
  cmd->callback([o, order, noise_bound] {
    o->order_given = order->count() > 0;
    o->noise_bound_given = noise_bound->count() > 0;
    CheckBoundsOptions(*o);
    if (!o->json_out.empty()) CheckOutputFile(o->json_out, "--json");
    const std::string plot_terminal = o->plot_out.empty() ? "" : CheckPlotOutput(o->plot_out);
    if (!o->run_dir.empty()) CheckOutputDirectory(o->run_dir, "--run-dir");
    const dss::HwData data = ReadData(*o);
    const dss::HwStructure structure = ReadStructure(*o);
    const auto names = dss::MakeLayout(structure).names;
    const dss::BoundsOptions options = MakeBoundsOptions(*o);
    if (o->set == "exact") MakeExactOptions(*o, options);  // its settings refused before any work
    const dss::HwOuterSet set(structure, data, o->horizon, parse_box(o->box, names));
    const std::vector<dss::BoxCut> cuts = parse_split(o->split);
    RequireOption("--split", [&](std::string* e) { return dss::ValidBoxCuts(cuts, names, set.box(), e); });
    for (const auto& w : set.warnings()) fmt::print(stderr, "WARNING: {}\n", w);
    if (!options.executor->is_coordinator()) {  // an MPI worker rank: serve jobs (same options), print nothing
      const auto outer = dss::ComputeBoundsInPieces(options, set, cuts);  // --auto-split is refused under mpi
      if (o->set == "exact") exact::ComputeExactBounds(MakeExactOptions(*o, options), structure, data, exact::StartBoxFromOuter(outer, set));
      return;
    }
    std::vector<double> truth;
    if (!o->truth.empty()) {
      truth = parse_list(o->truth, "--truth");
      if (truth.size() != names.size())
        throw InputError(fmt::format("--truth has {} values; the model has {} parameters", truth.size(), names.size()));
    }
    fmt::print("hwbounds bounds: {} samples from {}, na={} nb={} horizon n={} order delta={}, {} parameters, "
               "{} sign orthants, solver {}, jobs on {} ({} workers)\n",
               data.y.size(), o->data, o->na, o->nb, o->horizon, options.order, names.size(), set.num_orthants(),
               SolverText(options), options.executor->name(), options.executor->workers());
    std::fflush(stdout);  // the header before the progress lines on stderr
    ProgressDisplay display(ChooseProgressMode(stderr, o->quiet, o->verbose), stderr);
    dss::AutoSplitOptions auto_split;
    auto_split.rounds = o->auto_split;
    const auto summary = dss::ComputeBoundsWithAutoSplit(options, set, cuts, auto_split,
                                                           [&display](const dss::BoundsProgress& p) { display.Show(p); });
    display.Finish();
    const bool invalidated = summary.invalidated();
    const bool covered = dss::TruthCovered(summary, truth);
    dss::BoundsReportOptions report;
    report.truth = truth;
    report.model_class = fmt::format("na = {}, nb = {}, input basis {}, output basis {}, horizon {}", o->na, o->nb,
                                     o->input_basis, o->output_basis, o->horizon);
    report.verify = !o->no_verify;
    fmt::print("{}", dss::FullReport(summary, report));
    nlohmann::json result = ResultJson(summary, *o, set, truth, covered);
    result["set"] = "dss";
    bool exact_invalidated = false;
    std::optional<ExactPlotIntervals> exact_plot;
    if (o->set == "exact" && !invalidated) {
      std::fflush(stdout);
      ProgressDisplay exact_display(ChooseProgressMode(stderr, o->quiet, o->verbose), stderr);
      const auto exact_summary = exact::ComputeExactBounds(
          MakeExactOptions(*o, options), structure, data, exact::StartBoxFromOuter(summary, set),
          [&exact_display](const exact::ExactBoundsProgress& p) {
            dss::BoundsProgress line;
            line.phase = "exact set: " + p.phase;
            line.done = p.done;
            line.total = p.total;
            line.elapsed_seconds = p.elapsed_seconds;
            exact_display.Show(line);
          });
      exact_display.Finish();
      exact::ExactReportOptions exact_report;
      exact_report.truth = truth;
      for (const auto& iv : exact::StartBoxFromOuter(summary, set)) exact_report.outer.emplace_back(iv.lo, iv.hi);
      exact_report.outer_label = fmt::format("D^ss({})", o->horizon);
      exact_report.stage1_seconds = summary.wall_seconds;
      exact_report.model_class = report.model_class + ", noise bound per sample from the recording or --noise-bound";
      fmt::print("{}", exact::ExactReport(exact_summary, exact_report));
      result = exact::ExactResultJson(exact_summary, result, summary, truth);
      exact_invalidated = exact_summary.invalidated;
      if (!exact_invalidated) exact_plot = PlotIntervalsOf(exact_summary);
    }
    OutputFiles outputs;  // all or none, each renamed into place whole
    if (!o->json_out.empty()) outputs.Add(o->json_out, result.dump(2) + "\n");
    if (!o->plot_out.empty()) outputs.Add(o->plot_out, RenderBoundsPlot(summary, truth, plot_terminal, exact_plot ? &*exact_plot : nullptr));
    outputs.Commit();
    for (const auto& [path, bytes] : outputs.files()) fmt::print("wrote {}\n", path);
    if (invalidated || exact_invalidated) throw CommandExit{kExitInvalidated};
  });
}

}  // namespace hw::cli
