// hwbounds.bounds: guaranteed parameter intervals (dss::ComputeBounds over dss::HwOuterSet), the same
// engine and options as `hwbounds bounds`, with a progress callback and Ctrl-C.
#include <algorithm>
#include <cmath>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "python/py_convert.hpp"
#include "python/py_module.hpp"
#include "exact/exact_report.hpp"
#include "exact/two_stage.hpp"
#include "dss/bounds_report.hpp"
#include "dss/box_split.hpp"
#include "dss/set_membership.hpp"
#include "sdp/job_executor.hpp"
#include "sdp/sdp_solver.hpp"

namespace hw::python {
namespace {

// The prior box: None (every parameter in [-10, 10], as the CLI), (lo, hi) for every parameter, a dict
// {name: (lo, hi)} over that default, or one (lo, hi) per parameter.
std::vector<std::pair<double, double>> BoxFromPython(py::handle h, const std::vector<std::string>& names) {
  std::vector<std::pair<double, double>> box(names.size(), {-10.0, 10.0});
  // The interval of `name` ("" = every parameter): a pair here, its values checked by the library (the CLI's
  // --box gets the same message).
  auto pair = [&names](py::handle p, const std::string& name) {
    const std::string what = name.empty() ? "box" : "box['" + name + "']";
    const auto v = ToVector(p, what);
    if (v.size() != 2) throw py::value_error(fmt::format("{}: expected (LO, HI), got {} values", what, v.size()));
    Require([&](std::string* e) { return dss::ValidBoxEntry(name, v[0], v[1], names, e); });
    return std::pair<double, double>{v[0], v[1]};
  };
  if (h.is_none()) return box;
  if (py::isinstance<py::dict>(h)) {
    for (const auto& [k, v] : h.cast<py::dict>()) {
      const std::string name = py::str(k);
      const auto interval = pair(v, name);  // checks the name too
      box[std::find(names.begin(), names.end(), name) - names.begin()] = interval;
    }
    return box;
  }
  if (!py::isinstance<py::sequence>(h) || py::isinstance<py::str>(h))
    throw py::type_error("box: expected None, (lo, hi), {name: (lo, hi)} or one (lo, hi) per parameter");
  const auto seq = h.cast<py::sequence>();
  if (seq.size() == 2 && !py::isinstance<py::sequence>(seq[0])) {
    box.assign(names.size(), pair(h, ""));
    return box;
  }
  if (seq.size() != names.size())
    throw py::value_error(
        fmt::format("box: {} pairs for {} parameters ({})", seq.size(), names.size(), fmt::join(names, ", ")));
  for (std::size_t i = 0; i < names.size(); ++i) box[i] = pair(seq[i], names[i]);
  return box;
}

// The cuts of the prior box: None (no cut) or {name: value or [values]}, as the CLI's --split NAME=V1,V2; the
// values are checked against the box by the library (the CLI gets the same message).
std::vector<dss::BoxCut> SplitFromPython(py::handle h, const std::vector<std::string>& names,
                                           const std::vector<std::pair<double, double>>& box) {
  std::vector<dss::BoxCut> cuts;
  if (h.is_none()) return cuts;
  if (!py::isinstance<py::dict>(h))
    throw py::type_error("split: expected None or {name: value or [values]}, e.g. {'gamma2': 0.0}");
  for (const auto& [k, v] : h.cast<py::dict>()) {
    const std::string name = py::str(k);
    const std::string what = "split['" + name + "']";
    cuts.push_back({name, py::isinstance<py::float_>(v) || py::isinstance<py::int_>(v)
                              ? std::vector<double>{v.cast<double>()}
                              : ToVector(v, what)});
  }
  Require([&](std::string* e) { return dss::ValidBoxCuts(cuts, names, box, e); });
  return cuts;
}

std::vector<double> NoiseBound(py::handle h, std::size_t n) {
  if (py::isinstance<py::float_>(h) || py::isinstance<py::int_>(h)) {
    const double b = h.cast<double>();
    Require([&](std::string* e) { return dss::ValidNoiseBound(b, e); });
    return std::vector<double>(n, b);
  }
  return ToVector(h, "noise_bound");
}

py::dict ProgressDict(const dss::BoundsProgress& p) {
  py::dict d;
  d["phase"] = p.phase;
  d["done"] = p.done;
  d["total"] = p.total;
  d["elapsed_seconds"] = p.elapsed_seconds;
  d["eta_seconds"] = p.eta_seconds;
  d["from_cache"] = p.from_cache;
  return d;
}

struct BoundsArgs {
  dss::HwStructure structure;
  std::string input_basis, output_basis, executor;
  int horizon = 2;
  bool order_given = false;  // false: the minimal order of the horizon
  dss::BoundsOptions options;
  dss::AutoSplitOptions auto_split;
  std::string set = "dss";  // "dss" or "exact" (the exact set D inside the D^ss(n) box)
  exact::ExactBoundsOptions exact;
};

py::object Bounds(py::handle u, py::handle y, py::handle noise_bound, BoundsArgs a, py::handle box, py::handle split,
                  py::object progress, const std::string& source, bool with_report) {
  dss::HwData data;
  data.source = source;
  data.u = ToVector(u, "u");
  data.y = ToVector(y, "y");
  data.noise_bound = NoiseBound(noise_bound, data.y.size());
  a.structure.input_basis = dss::parse_basis(a.input_basis);
  a.structure.output_basis = dss::parse_basis(a.output_basis);
  RequireValid(a.structure);
  RequireValid(data);
  // The CLI's checks of the same settings (dss::SettingChecks).
  dss::BoundsSettings settings;
  settings.horizon = a.horizon;
  if (a.order_given) settings.order = a.options.order;
  settings.solver = a.options.solver;
  settings.threads = a.options.threads;
  settings.executor = a.executor;
  settings.contraction_passes = a.options.contraction_passes;
  settings.row_block_order = a.options.generation.block_order_cap;
  settings.stopped_short_refinements = a.options.stopped_short_refinements;
  settings.endpoint_refinements = a.options.endpoint_refinements;
  settings.auto_split_rounds = a.auto_split.rounds;
  for (const auto& check : dss::SettingChecks(settings)) Require(check.valid);
  a.options.order = a.order_given ? a.options.order : dss::MinimalOrder(a.horizon);
  if (a.executor == "mpi")
    throw py::value_error(
        "executor 'mpi' runs under mpirun from the CLI (`hwbounds bounds --executor mpi`); use "
        "'fork' or 'inprocess' from Python");
  a.options.executor = sdp::MakeExecutor(a.executor, a.options.threads);
  RequireValid(a.options);
  const auto names = dss::MakeLayout(a.structure).names;
  const dss::HwOuterSet set(a.structure, data, a.horizon, BoxFromPython(box, names));
  const std::vector<dss::BoxCut> cuts = SplitFromPython(split, names, set.box());
  // Ctrl-C is checked while the engine waits for its jobs and at every progress report.
  a.options.executor->set_interrupt_check(CheckPythonSignals);
  auto on_progress = [&progress](const dss::BoundsProgress& p) {
    py::gil_scoped_acquire gil;
    if (PyErr_CheckSignals() != 0) throw py::error_already_set();
    if (!progress.is_none()) progress(ProgressDict(p));
  };
  const auto summary = WithoutGil([&] {
    return dss::ComputeBoundsWithAutoSplit(a.options, set, cuts, a.auto_split, on_progress);
  });
  nlohmann::json j = summary.to_json();
  j["data"] = source;
  j["data_warnings"] = set.warnings();  // as the CLI writes them
  j["structure"] = {{"na", a.structure.na},
                    {"nb", a.structure.nb},
                    {"proper", !a.structure.strictly_proper},
                    {"input_basis", a.input_basis},
                    {"output_basis", a.output_basis}};
  if (a.set == "exact" && !summary.invalidated()) {
    a.exact.executor = a.options.executor;
    a.exact.run_dir = a.options.run_dir;
    a.exact.parameters = a.options.parameters;
    const exact::ExactBoundsSummary exact_summary = WithoutGil([&] {
      return exact::ComputeExactBounds(a.exact, a.structure, data, exact::StartBoxFromOuter(summary, set));
    });
    nlohmann::json e = exact::ExactResultJson(exact_summary, j, summary, {});
    if (with_report) {
      exact::ExactReportOptions r;
      for (const auto& iv : exact::StartBoxFromOuter(summary, set)) r.outer.emplace_back(iv.lo, iv.hi);
      r.outer_label = fmt::format("D^ss({})", a.horizon);
      r.stage1_seconds = summary.wall_seconds;
      r.model_class = fmt::format("na = {}, nb = {}, input basis {}, output basis {}", a.structure.na, a.structure.nb,
                                  a.input_basis, a.output_basis);
      e["full_report"] = exact::ExactReport(exact_summary, r);
    }
    return ToPython(e);
  }
  j["set"] = "dss";
  if (with_report) {  // the text the CLI prints after a run
    dss::BoundsReportOptions r;
    r.model_class = fmt::format("na = {}, nb = {}, input basis {}, output basis {}, horizon {}", a.structure.na,
                                a.structure.nb, a.input_basis, a.output_basis, a.horizon);
    r.verify = a.options.generation.verify.enabled;
    j["brief_report"] = dss::BriefReport(summary, r);
    j["full_report"] = dss::FullReport(summary, r);
  }
  return ToPython(j);
}

}  // namespace

void DefineBounds(py::module_& m) {
  const dss::HwStructure s;
  const dss::BoundsOptions o;
  const pop::ConstraintGenerationOptions& g = o.generation;
  m.def(
      "bounds",
      [](py::handle u, py::handle y, py::handle noise_bound, int na, int nb, std::string input_basis,
         std::string output_basis, int horizon, py::object order, bool strictly_proper, py::handle box, py::handle split,
         int auto_split, std::string solver,
         int threads, std::string executor, std::string run_dir, std::vector<std::string> parameters, bool cheap_pass,
         bool edge_witnesses, bool moment_witnesses, bool lp_screen, bool retry_with_other_solver, bool full_pass_contraction,
         int contraction_passes, double contraction_min_shrink, int contraction_max_rounds,
         int row_block_order, int stopped_short_refinements, int endpoint_refinements, int max_rounds, int add_per_round, double violation_tolerance, bool verify,
         py::object progress, std::string source, bool report, std::string set, int lp_budget, int sweeps, double target_ratio, std::string lp_solver) {
        BoundsArgs a;
        if (set != "dss" && set != "exact")
          throw py::value_error(fmt::format("set '{}' unknown; expected 'dss' or 'exact'", set));
        a.set = set;
        a.exact.search.lp_budget = lp_budget;
        a.exact.sweeps = sweeps;
        a.exact.target_ratio = target_ratio;
        a.exact.lp_solver = lp_solver;
        if (std::string error; !a.exact.IsValid(&error)) throw py::value_error(error);
        a.structure.na = na;
        a.structure.nb = nb;
        a.structure.strictly_proper = strictly_proper;
        a.input_basis = std::move(input_basis);
        a.output_basis = std::move(output_basis);
        a.horizon = horizon;
        a.executor = std::move(executor);
        a.auto_split.rounds = auto_split;
        auto& op = a.options;
        // None = the minimal order ceil((n + 1) / 2) (at least 1), as the CLI's default "--order minimal".
        a.order_given = !order.is_none();
        if (a.order_given) op.order = order.cast<int>();
        op.solver = std::move(solver);
        op.threads = threads;
        op.run_dir = std::move(run_dir);
        op.parameters = std::move(parameters);
        op.cheap_pass = cheap_pass;
        op.edge_witness.enabled = edge_witnesses;
        op.moment_witnesses = moment_witnesses;
        op.lp_screen = lp_screen;
        op.generation.retry_undecided_rounds = retry_with_other_solver;
        op.contract_before_full_pass = full_pass_contraction;
        op.contraction_passes = contraction_passes;
        op.contraction_min_shrink = contraction_min_shrink;
        op.contraction_max_rounds = contraction_max_rounds;
        op.generation.block_order_cap = row_block_order;
        op.stopped_short_refinements = stopped_short_refinements;
        op.endpoint_refinements = endpoint_refinements;
        op.generation.max_rounds = max_rounds;
        op.generation.add_per_round = add_per_round;
        op.generation.violation_tolerance = violation_tolerance;
        op.generation.verify.enabled = verify;
        return Bounds(u, y, noise_bound, std::move(a), box, split, std::move(progress), source, report);
      },
      R"doc(Guaranteed parameter intervals of a Hammerstein-Wiener model from a recording (paper 001), as
`hwbounds bounds`. u, y: 1-D arrays; noise_bound: |eta_t| <= noise_bound (a number, or one per sample).
Options mirror dss::HwStructure and dss::BoundsOptions (same names, defaults and validation messages);
row_block_order is the CLI's --row-block-order (generation.block_order_cap: -1 = full order, 1 at order 3 = the
mixed relaxation with 9x9 data-row blocks).
box: None (every parameter in [-10, 10]), (lo, hi), {name: (lo, hi)} or one pair per parameter.
split: None or {name: value or [values]}, the CLI's --split: the box is cut there, each piece bounded on its own,
and the intervals are the hull over the pieces (each piece's own result under "pieces").
auto_split: the CLI's --auto-split, 0..5 rounds: after the run, the box shrunk to the verified intervals is cut
just beyond the last certified feasible point of the largest unwitnessed part and bounded again (each round's
box, cut and intervals under "auto_split").
progress: called as progress(dict(phase, done, total, from_cache, elapsed_seconds, eta_seconds)) after each job
(done/total count the jobs still to run; from_cache those read from run_dir).
Returns the CLI's JSON as a dict: intervals (lower/upper value, status, verification), prior_box, orthants,
counts, timing, ... The GIL is released while the engine runs; Ctrl-C stops the run (KeyboardInterrupt) and
its worker processes; with run_dir a rerun resumes from the finished jobs.
set: "dss" (the default: D^ss(n)) or "exact": the exact set D bounded inside the D^ss(n) box (CLI --set exact;
docs/exact_set.md); lp_budget, sweeps, target_ratio and lp_solver are the CLI's --lp-budget, --sweeps, --target-ratio and --lp-solver. With "exact" the dict has
"set": "exact", intervals of D (with the inner hull), "outer_set_intervals", "stage2" counts and "assumption".
report: also return the text `hwbounds bounds` prints, as "brief_report" (the interval table and warnings, or the
verdict) and "full_report" (all of it: pieces, rounds, counts, times, where the bounds came from).)doc",
      py::arg("u"), py::arg("y"), py::arg("noise_bound"), py::arg("na") = s.na, py::arg("nb") = s.nb,
      py::arg("input_basis") = "poly:3", py::arg("output_basis") = "poly:3", py::arg("horizon") = 2,
      py::arg("order") = py::none(), py::kw_only(), py::arg("strictly_proper") = s.strictly_proper,
      py::arg("box") = py::none(), py::arg("split") = py::none(),
      py::arg("auto_split") = 0, py::arg("solver") = o.solver, py::arg("threads") = o.threads,
      py::arg("executor") = "fork", py::arg("run_dir") = o.run_dir, py::arg("parameters") = o.parameters,
      py::arg("cheap_pass") = o.cheap_pass, py::arg("edge_witnesses") = o.edge_witness.enabled,
      py::arg("moment_witnesses") = o.moment_witnesses,
      py::arg("lp_screen") = o.lp_screen,
      py::arg("retry_with_other_solver") = o.generation.retry_undecided_rounds,
      py::arg("full_pass_contraction") = o.contract_before_full_pass,
      py::arg("contraction_passes") = o.contraction_passes,
      py::arg("contraction_min_shrink") = o.contraction_min_shrink,
      py::arg("contraction_max_rounds") = o.contraction_max_rounds, py::arg("row_block_order") = g.block_order_cap,
      py::arg("stopped_short_refinements") = o.stopped_short_refinements,
      py::arg("endpoint_refinements") = o.endpoint_refinements, py::arg("max_rounds") = g.max_rounds,
      py::arg("add_per_round") = g.add_per_round, py::arg("violation_tolerance") = g.violation_tolerance,
      py::arg("verify") = g.verify.enabled, py::arg("progress") = py::none(), py::arg("source") = "data",
      py::arg("report") = false, py::arg("set") = "dss",
      py::arg("lp_budget") = exact::ObjectiveSearchOptions{}.lp_budget, py::arg("sweeps") = exact::ExactBoundsOptions{}.sweeps,
      py::arg("target_ratio") = exact::ExactBoundsOptions{}.target_ratio,
      py::arg("lp_solver") = exact::ExactBoundsOptions{}.lp_solver);
}

}  // namespace hw::python
