// `hwbounds bounds`: guaranteed parameter intervals of a Hammerstein–Wiener model from a recording.
#include <algorithm>
#include <cmath>
#include <map>
#include <sstream>
#include <thread>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "cli/commands.hpp"
#include "core/csv_table.hpp"
#include "core/output_files.hpp"
#include "core/progress_throttle.hpp"
#include "core/recording.hpp"
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

// Exit status of a run whose data prove that no parameter in the prior box fits (README, `bounds --help`).
constexpr int kExitInvalidated = 3;

struct BoundsCliOptions {
  std::string data, u_col = "u", y_col = "y", noise_col, input_basis = "poly:3", output_basis = "poly:3";
  std::string solver = "auto", json_out, run_dir, truth, executor = "fork";
  std::vector<std::string> box, params, split;
  double noise_bound = 0.0;
  int na = 2, nb = 2, horizon = 2, order = 0, threads = 0;
  bool order_given = false, noise_bound_given = false;  // --order, --noise-bound on the command line
  bool proper = false, no_cheap = false, no_edge_witnesses = false, no_moment_witnesses = false, no_full_pass_contraction = false, solver_retry = false, quiet = false, verify = false, no_verify = false;
  int contraction_passes = 0;
  int stopped_short_refinements = dss::BoundsOptions{}.stopped_short_refinements;
  int endpoint_refinements = 0;
  int row_block_order = -1;
  int auto_split = 0;
};

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
  RequireOption("--horizon", [&](std::string* e) { return dss::ValidHorizon(o.horizon, e); });
  if (o.order_given) RequireOption("--order", [&](std::string* e) { return dss::ValidOrder(o.order, o.horizon, e); });
  RequireOption("--solver", [&](std::string* e) { return dss::ValidBoundsSolver(o.solver, e); });
  RequireOption("--threads", [&](std::string* e) { return dss::ValidThreads(o.threads, e); });
  RequireOption("--executor", [&](std::string* e) { return sdp::ValidExecutorName(o.executor, e); });
  RequireOption("--contract-passes", [&](std::string* e) { return dss::ValidContractionPasses(o.contraction_passes, e); });
  RequireOption("--row-block-order", [&](std::string* e) { return pop::ValidBlockOrderCap(o.row_block_order, e); });
  RequireOption("--stopped-short-refinements",
                [&](std::string* e) { return dss::ValidStoppedShortRefinements(o.stopped_short_refinements, e); });
  RequireOption("--endpoint-refinements",
                [&](std::string* e) { return dss::ValidEndpointRefinements(o.endpoint_refinements, e); });
  RequireOption("--auto-split", [&](std::string* e) { return dss::ValidAutoSplitRounds(o.auto_split, o.executor, e); });
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
  if (!o.quiet)  // one line per constraint-generation round, printed by the process that runs the job
    options.round_log = [](const std::string& line) { fmt::print(stderr, "  {}\n", line); };
  std::string error;
  if (!options.IsValid(&error)) throw InputError(error);
  return options;
}

// The interval table; returns whether every given true value lies inside its interval.
bool PrintIntervals(const dss::BoundsSummary& summary, const std::vector<std::string>& names,
                    const std::vector<double>& truth) {
  fmt::print("\n{:<10} {:>12} {:>12} {:>11}  {:<10} {:>19}  {:<25}  {}\n", "parameter", "lower", "upper", "half-width",
             "verified", "correction lo/up", "feasible points reach", "status");
  bool covered = true;
  for (const auto& iv : summary.intervals) {
    const std::size_t k = std::find(names.begin(), names.end(), iv.name) - names.begin();
    std::string status = iv.lower.status == "guaranteed" && iv.upper.status == "guaranteed"
                             ? "guaranteed"
                             : fmt::format("lower {}, upper {}", iv.lower.status, iv.upper.status);
    if (!truth.empty()) {
      const bool in = iv.lower.value <= truth[k] && truth[k] <= iv.upper.value;
      covered = covered && in;
      status += fmt::format("  truth {:.6g} {}", truth[k], in ? "inside" : "OUTSIDE");
    }
    const std::string verified = iv.lower.verification == iv.upper.verification
                                     ? iv.lower.verification
                                     : iv.lower.verification + "/" + iv.upper.verification;
    // The inner side: certified points of the set reach this range, so the exact interval lies between the two.
    const std::string reached = iv.witnessed_lower && iv.witnessed_upper
                                    ? fmt::format("[{:.6f}, {:.6f}]", *iv.witnessed_lower, *iv.witnessed_upper)
                                    : "-";
    fmt::print("{:<10} {:>12.6f} {:>12.6f} {:>11.6f}  {:<10} {:>9.1e}/{:<9.1e}  {:<25}  {}\n", iv.name, iv.lower.value,
               iv.upper.value, iv.half_width(), verified, iv.lower.correction, iv.upper.correction, reached, status);
    for (const auto* ep : {&iv.lower, &iv.upper})
      if (!ep->note.empty()) fmt::print("           note: {}\n", ep->note);
  }
  return covered;
}

// How one orthant was proven empty, for a person: "LP screen, verified in interval arithmetic".
std::string CertificateText(const dss::EmptinessCertificate& c) {
  const std::string how = c.kind == "lp"               ? "LP screen infeasible"
                          : c.kind == "relaxation"     ? fmt::format("order {} relaxation infeasible", c.order)
                          : c.kind == "pieces"         ? "proven empty in every piece of the split box"
                                                       : fmt::format("order {} bounds cross", c.order);
  return fmt::format("{}{}, {}", how, c.contracted_box ? " in the contracted box" : "",
                     c.verified ? "verified in interval arithmetic" : "the solver's floating-point certificate (unverified)");
}

// The verdict of an empty feasible set: what it means, which certificates prove it, where to look next.
void PrintInvalidation(const dss::BoundsSummary& summary, const BoundsCliOptions& o) {
  fmt::print("\nVERDICT: model invalidated. No parameter in the prior box explains the data within the noise bound: "
             "the model class (na = {}, nb = {}, input basis {}, output basis {}, horizon {}) or the noise bound is "
             "wrong.\n",
             o.na, o.nb, o.input_basis, o.output_basis, o.horizon);
  std::map<std::string, int> by_certificate;
  int verified = 0;
  for (const auto& r : summary.orthants) {
    ++by_certificate[r.status];
    verified += r.certificate && r.certificate->verified ? 1 : 0;
  }
  std::string counts;
  for (const auto& [kind, n] : by_certificate) counts += fmt::format("{}{} {}", counts.empty() ? "" : ", ", n, kind);
  fmt::print("certificates: all {} sign orthants are proven empty ({}); {} of them verified in interval arithmetic{}:\n",
             summary.orthants_total, counts, verified, o.no_verify ? " (--no-verify)" : "");
  for (const auto& r : summary.orthants)
    fmt::print("  orthant {:>3} ({}): {}\n", r.index, r.signs, r.certificate ? CertificateText(*r.certificate) : r.status);
  fmt::print("next: `hwbounds diagnose --data REC --validate REC2 --fit hw:NA,NB,PIN,POUT` looks for what the model "
             "leaves out (docs/diagnose.md); a larger noise bound, other bases or orders, or a wider --box change the "
             "question.\n");
}

// One line per piece of a split box: its box side(s) that differ from the prior box, and what it gave.
void PrintPieces(const dss::BoundsSummary& summary) {
  if (summary.pieces.empty()) return;
  fmt::print("\nthe prior box split into {} pieces; the intervals above are the hull over the pieces:\n",
             summary.pieces.size());
  for (std::size_t k = 0; k < summary.pieces.size(); ++k) {
    const auto& piece = summary.pieces[k];
    std::string sides;
    const auto& box = piece.at("prior_box");
    for (std::size_t i = 0; i < box.size() && i < summary.box.size(); ++i)
      if (box[i].at("lo").get<double>() != summary.box[i].first || box[i].at("hi").get<double>() != summary.box[i].second)
        sides += fmt::format("{}{} in [{:.6g}, {:.6g}]", sides.empty() ? "" : ", ", box[i].at("parameter").get<std::string>(),
                             box[i].at("lo").get<double>(), box[i].at("hi").get<double>());
    std::string result;
    if (piece.at("invalidated").get<bool>()) {
      result = "every orthant proven empty";
    } else {
      for (const auto& iv : piece.at("intervals"))
        result += fmt::format("{}{} [{:.6f}, {:.6f}]", result.empty() ? "" : ", ", iv.at("parameter").get<std::string>(),
                              iv.at("lower").at("value").get<double>(), iv.at("upper").at("value").get<double>());
    }
    fmt::print("  piece {} ({}): {}; wall {:.1f} s\n", k + 1, sides, result,
               piece.at("timing").at("wall_seconds").get<double>());
  }
}

// One line per automatic round: the cut it added, the box it ran in (the sides the earlier rounds proved), and
// what it gave.
void PrintAutoSplitRounds(const dss::BoundsSummary& summary) {
  if (summary.auto_split.is_null()) return;
  const auto& rounds = summary.auto_split.at("rounds");
  fmt::print("\nautomatic cuts: {} round(s) after the first run ({}); each bounds D^ss(n) in the prior box, the "
             "last one's intervals are those above:\n",
             rounds.size() - 1, summary.auto_split.at("stopped").get<std::string>());
  for (const auto& round : rounds) {
    const auto& cut = round.at("cut");
    std::string what = cut.is_null() ? std::string("first run")
                                     : fmt::format("cut {} = {:.6g} ({:.0f}% of its interval unwitnessed)",
                                                   cut.at("parameter").get<std::string>(), cut.at("value").get<double>(),
                                                   100 * cut.at("unwitnessed_fraction").get<double>());
    std::string intervals;
    for (const auto& iv : round.at("intervals"))
      intervals += fmt::format("{}{} [{:.6f}, {:.6f}]", intervals.empty() ? "" : ", ",
                               iv.at("parameter").get<std::string>(), iv.at("lower").get<double>(),
                               iv.at("upper").get<double>());
    fmt::print("  round {} ({}, {} piece(s)): {}; wall {:.1f} s\n", round.at("round").get<int>(), what,
               round.at("pieces").get<std::size_t>(),
               round.at("invalidated").get<bool>() ? std::string("every orthant proven empty") : intervals,
               round.at("wall_seconds").get<double>());
  }
}

// Where the relaxation may overestimate most: the largest part of an interval no certified point reaches, from
// 10 % of its width on, with the cut that bounds that part on its own.
void PrintUnwitnessedPart(const dss::BoundsSummary& summary) {
  const auto part = dss::LargestUnwitnessedPart(summary);
  if (!part || part->fraction < 0.1) return;
  fmt::print("\nlargest unwitnessed part: no certified feasible point has {} in {} ({:.0f}% of its interval); the "
             "relaxation may overestimate there. A cut just {} {:.6g} (--split {}=VALUE, or --auto-split 1 to place it) "
             "bounds that part on its own and may prove it empty (README, \"Box split\").\n",
             part->parameter,
             part->below ? fmt::format("[{:.6g}, {:.6g})", part->bound, part->witnessed)
                         : fmt::format("({:.6g}, {:.6g}]", part->witnessed, part->bound),
             100 * part->fraction, part->below ? "below" : "above", part->witnessed, part->parameter);
}

void PrintRunSummary(const dss::BoundsSummary& summary, const std::vector<std::string>& names, bool verify) {
  fmt::print("\nprior box (assumption): ");
  for (std::size_t i = 0; i < names.size(); ++i)
    fmt::print("{}{} in [{}, {}]", i ? ", " : "", names[i], summary.box[i].first, summary.box[i].second);
  for (const auto& [l, b] : summary.orthant_boxes) {
    fmt::print("\ncontracted box of orthant {} (proven to hold its points of D^ss(n) in the prior box): ", l);
    for (std::size_t i = 0; i < names.size(); ++i)
      fmt::print("{}{} in [{:.6g}, {:.6g}]", i ? ", " : "", names[i], b[i].first, b[i].second);
  }
  fmt::print("\nrelaxation: {}", summary.relaxation);
  fmt::print("\northants: {} total, {} proven empty, {} solved, {} failed; {} relaxation jobs ({} SDP solves, "
             "{} from cache), largest SDP {} moments / {} blocks, median solve {:.2f} s, wall {:.1f} s\n",
             summary.orthants_total, summary.orthants_empty, summary.orthants_solved, summary.orthants_failed,
             summary.sdp_jobs, summary.sdp_solves, summary.jobs_from_cache, summary.largest_moments,
             summary.largest_blocks, summary.median_solve_seconds, summary.wall_seconds);
  if (summary.edge_witness_solves > 0)
    fmt::print("feasible points at the box edges: {} endpoint(s) settled without an SDP ({} local solves, {:.1f} s)\n",
               summary.edge_witness_settled, summary.edge_witness_solves, summary.edge_witness_seconds);
  if (summary.moment_witness_jobs > 0)
    fmt::print("feasible points from the relaxations' moments: {} of {} local searches certified ({:.1f} s)\n",
               summary.moment_witness_found, summary.moment_witness_jobs, summary.moment_witness_seconds);
  if (summary.jobs_stopped_beyond_witness > 0)
    fmt::print("{} relaxation job(s) ended early: their bound passed a certified feasible point's value, so further "
               "rounds could not move the endpoint\n", summary.jobs_stopped_beyond_witness);
  if (summary.refine_jobs > 0)
    fmt::print("{} endpoint job(s) solved again in a contracted box after a solve stopped short; {} bound(s) "
               "tightened\n", summary.refine_jobs, summary.refine_tightened);
  if (summary.endpoint_refine_jobs > 0)
    fmt::print("{} endpoint job(s) solved again in the box of the full pass's own bounds; {} bound(s) tightened\n",
               summary.endpoint_refine_jobs, summary.endpoint_refine_tightened);
  if (summary.jobs_settled_by_sign > 0)
    fmt::print("{} relaxation job(s) not run: the orthant's sign constraints already bound them at or beyond a "
               "certified feasible point's value\n", summary.jobs_settled_by_sign);
  for (const auto& r : summary.row_reduction) {
    std::string steps;
    for (const auto& c : r.at("per_step"))
      if (c.contains("error"))
        steps += fmt::format("{}step {}: reduction failed ({}), every row of the orthant kept", steps.empty() ? "" : ", ",
                             c.value("step", 0), c.at("error").get<std::string>());
      else if (c.contains("step"))
        steps += fmt::format("{}step {}: {} of {}{}", steps.empty() ? "" : ", ", c.at("step").get<int>(),
                             c.at("kept").get<int>(), c.at("rows").get<int>(),
                             c.value("iteration_limited", 0) > 0
                                 ? fmt::format(" ({} kept after their LP hit the simplex iteration limit)",
                                               c.at("iteration_limited").get<int>())
                                 : std::string());
    fmt::print("exact row reduction, orthant {}: data rows kept {}\n", r.at("orthant").get<int>(), steps);
  }
  if (!summary.bound_sources.empty()) {
    std::string sources;
    for (const auto& [what, count] : summary.bound_sources)
      sources += fmt::format("{}{} {}", sources.empty() ? "" : ", ", count, what);
    fmt::print("orthant bounds entering the endpoints: {}\n", sources);
  }
  if (summary.clipped_to_box) fmt::print("note: endpoints beyond the prior box are intersected with it\n");
  if (verify)
    fmt::print("verification: {:.2f} s for {:.2f} s of SDP solves ({:.1f}%)\n", summary.verify_seconds,
               summary.solve_seconds,
               summary.solve_seconds > 0 ? 100 * summary.verify_seconds / summary.solve_seconds : 0.0);
}

void PrintWarnings(const dss::BoundsSummary& summary, bool verify) {
  if (!summary.all_guaranteed())
    fmt::print("WARNING: some endpoints are conservative fallbacks (still valid bounds) or floating-point bounds that "
               "verification could not prove (see notes and the verified column).\n");
  if (!verify) return;
  for (const auto& iv : summary.intervals)
    for (const auto* ep : {&iv.lower, &iv.upper})
      if (ep->verification == "unverified") {
        fmt::print("WARNING: {} has an endpoint that rests on an unverified floating-point bound (see notes).\n",
                   iv.name);
        break;
      }
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
                  "often tighter (README, \"The relaxation gap\")");
  cmd->add_option("--auto-split", o->auto_split,
                  "after the run, up to this many rounds (0..5): shrink the box to the verified intervals, cut off "
                  "the largest part of an interval no certified feasible point reaches (from 10% of its width) just "
                  "beyond that point, and bound again over the pieces (README, \"Box split\")");
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
  cmd->add_option("--json", o->json_out, "write the result as JSON");
  cmd->add_flag("--quiet", o->quiet, "no progress lines");
  cmd->callback([o, order, noise_bound] {
    o->order_given = order->count() > 0;
    o->noise_bound_given = noise_bound->count() > 0;
    CheckBoundsOptions(*o);
    if (!o->json_out.empty()) CheckOutputFile(o->json_out, "--json");
    if (!o->run_dir.empty()) CheckOutputDirectory(o->run_dir, "--run-dir");
    const dss::HwData data = ReadData(*o);
    const dss::HwStructure structure = ReadStructure(*o);
    const auto names = dss::MakeLayout(structure).names;
    const dss::BoundsOptions options = MakeBoundsOptions(*o);
    const dss::HwOuterSet set(structure, data, o->horizon, parse_box(o->box, names));
    const std::vector<dss::BoxCut> cuts = parse_split(o->split);
    RequireOption("--split", [&](std::string* e) { return dss::ValidBoxCuts(cuts, names, set.box(), e); });
    for (const auto& w : set.warnings()) fmt::print(stderr, "WARNING: {}\n", w);
    if (!options.executor->is_coordinator()) {  // an MPI worker rank: serve jobs (same options), print nothing
      dss::ComputeBoundsInPieces(options, set, cuts);  // --auto-split is refused under mpi
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
    ProgressThrottle throttle(5.0);  // a line per phase start and end, and at most one every 5 s in between
    auto progress = [o, &throttle](const dss::BoundsProgress& p) {
      if (o->quiet) return;
      if (p.total < 0) {  // a one-off message
        fmt::print(stderr, "{}\n", p.phase);
        return;
      }
      if (!throttle.Due(p.elapsed_seconds, p.done <= 0 || p.done >= p.total)) return;
      fmt::print(stderr, "[{}] {}/{} jobs{}, elapsed {:.0f} s, ETA {:.0f} s\n", p.phase, p.done, p.total,
                 p.from_cache > 0 ? fmt::format(" (+{} from the run directory)", p.from_cache) : std::string(),
                 p.elapsed_seconds, p.eta_seconds);
    };
    dss::AutoSplitOptions auto_split;
    auto_split.rounds = o->auto_split;
    const auto summary = dss::ComputeBoundsWithAutoSplit(options, set, cuts, auto_split, progress);
    const bool invalidated = summary.invalidated();
    bool covered = true;
    if (invalidated) PrintInvalidation(summary, *o);
    else covered = PrintIntervals(summary, names, truth);
    PrintPieces(summary);
    PrintAutoSplitRounds(summary);
    PrintRunSummary(summary, names, !o->no_verify);
    if (!invalidated) PrintWarnings(summary, !o->no_verify);
    PrintUnwitnessedPart(summary);
    if (!o->json_out.empty()) {
      write_text_atomic(o->json_out, ResultJson(summary, *o, set, truth, covered).dump(2) + "\n");
      fmt::print("wrote {}\n", o->json_out);
    }
    if (invalidated) throw CommandExit{kExitInvalidated};
  });
}

}  // namespace hw::cli
