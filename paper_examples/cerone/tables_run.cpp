#include "paper_examples/cerone/tables_run.hpp"

#include <algorithm>

#include <fmt/format.h>

#include "core/progress_throttle.hpp"
#include "paper_examples/cerone/paper_table.hpp"

namespace hw::cerone {

dss::HwOuterSet ExampleSet(const CeroneExample& ex, int horizon, double box) {
  dss::HwData data{ex.u, ex.y, std::vector<double>(ex.y.size(), ex.noise_bound), "cerone2011 example"};
  return dss::HwOuterSet(dss::CeroneExampleStructure(), data, horizon,
                           std::vector<std::pair<double, double>>(8, {-box, box}));
}

std::vector<int> ParameterIndices(const dss::HwOuterSet& set, const std::vector<std::string>& names) {
  const auto& all = set.layout().names;
  std::vector<int> indices;
  for (int k = 0; k < set.num_vars(); ++k)
    if (names.empty() || std::count(names.begin(), names.end(), all[k])) indices.push_back(k);
  return indices;
}

namespace {

// The engine at one order; the orders of one case share a run cache (the order-3 run reads back the order-2 jobs).
dss::BoundsSummary RunOuter(const TablesOptions& options, const dss::HwOuterSet& set, const TableCase& c,
                              int order, const Log& log) {
  dss::BoundsOptions bounds = options.bounds;
  bounds.order = order;
  bounds.parameters = options.params;
  if (!bounds.run_dir.empty())
    bounds.run_dir += fmt::format("/N{}_seed{}_snr{:g}_n{}", c.samples, c.seed, c.snr_db, c.horizon);
  log(fmt::format("{}: outer intervals at order {} ...", c.label(), order));
  // A line per finished job at most every 10 s of the phase and at its end (runs at order 3 take minutes per job;
  // screens and reductions finish hundreds of jobs a second), and the engine's messages ("resuming: ...").
  ProgressThrottle throttle(10.0);
  auto summary = dss::ComputeBounds(bounds, set, [&](const dss::BoundsProgress& p) {
    if (p.total < 0) return log("  " + p.phase);
    const bool phase_end = p.done >= p.total;
    if (p.done <= 0 || !throttle.Due(p.elapsed_seconds, phase_end)) return;
    if (phase_end) throttle.Reset();  // the next phase's clock starts at 0
    // done / total count the jobs still to run; those read back from the run cache are named apart.
    log(fmt::format("  [{}] {} of {} jobs{}, {:.0f} s{}", p.phase, p.done, p.total,
                    p.from_cache > 0 ? fmt::format(" (and {} read from the run cache)", p.from_cache) : "",
                    p.elapsed_seconds, p.done < p.total ? fmt::format(", about {:.0f} s left", p.eta_seconds) : ""));
  });
  log(fmt::format("{}: order {} done in {:.1f} s", c.label(), order, summary.wall_seconds));
  return summary;
}

}  // namespace

std::vector<std::pair<double, double>> OuterIntervalBox(const TableCase& c) {
  auto box = c.outer_box;
  for (const auto& [order, run] : c.outer)
    for (const auto& iv : run.intervals) {
      const auto k = std::find(c.names.begin(), c.names.end(), iv.name) - c.names.begin();
      if (k >= static_cast<long>(box.size()) || !(iv.lower.value <= iv.upper.value)) continue;
      const double pad = 1e-9 * std::max(1.0, iv.upper.value - iv.lower.value);
      box[k].first = std::max(box[k].first, iv.lower.value - pad);
      box[k].second = std::min(box[k].second, iv.upper.value + pad);
    }
  return box;
}

TableCase RunCase(const TablesOptions& options, int horizon, double snr_db, uint64_t seed, const Log& log,
                  const TableCase* shorter) {
  const auto ex = SimulateCeroneExample(seed, options.samples, snr_db);
  const auto set = ExampleSet(ex, horizon, options.box);
  const auto outer_set = shorter ? set.WithBox(OuterIntervalBox(*shorter)) : set;
  TableCase c;
  c.horizon = horizon;
  c.snr_db = snr_db;
  c.realised_snr_db = ex.snr_db;
  c.noise_bound = ex.noise_bound;
  c.seed = seed;
  c.samples = options.samples;
  c.names = set.layout().names;
  c.truth = CeroneExample::TrueParameters();
  c.outer_box = outer_set.box();
  c.box_from_horizon = shorter ? shorter->horizon : 0;
  if (shorter)
    log(fmt::format("{}: outer runs start in the box of the n = {} outer intervals (D^ss({}) lies inside D^ss({}))",
                    c.label(), c.box_from_horizon, horizon, c.box_from_horizon));
  // The outer intervals first: their runs' certified feasible points seed the inner hull (the engine searches
  // every live orthant, the hull's own starts only the truth's and those around it).
  for (int order : options.orders)
    if (options.outer_wanted(order, horizon, snr_db)) c.outer[order] = RunOuter(options, outer_set, c, order, log);
  std::vector<std::vector<double>> engine_points;
  for (const auto& [order, run] : c.outer)
    for (const auto& p : run.feasible_points) engine_points.push_back(p.point);
  c.inner = ComputeInnerHull(set, c.truth, ParameterIndices(set, options.params), options.inner, engine_points, log);
  log(fmt::format("{}: inner hull from {} witnesses ({} of {} given by the engine), {} local solves, {:.1f} s",
                  c.label(), c.inner.witnesses, c.inner.given_witnesses, engine_points.size(), c.inner.local_solves,
                  c.inner.seconds));
  return c;
}

std::vector<TableCase> RunTables(const TablesOptions& options, const Log& log) {
  std::vector<int> horizons = options.horizons;
  std::sort(horizons.begin(), horizons.end());
  std::vector<TableCase> cases;
  for (double snr : options.snrs)
    for (uint64_t seed : options.seeds)
      for (std::size_t i = 0; i < horizons.size(); ++i) {
        const bool nest = i > 0 && options.nest_horizons && !cases.back().outer.empty();
        cases.push_back(RunCase(options, horizons[i], snr, seed, log, nest ? &cases.back() : nullptr));
      }
  return cases;
}

std::vector<WidthRatio> InnerWidthRatios(const TablesOptions& options, double snr_db, uint64_t seed, const Log& log) {
  const auto ex = SimulateCeroneExample(seed, options.samples, snr_db);
  std::vector<WidthRatio> ratios;
  for (int n : options.horizons) {
    const auto set = ExampleSet(ex, n, options.box);
    log(fmt::format("equivalent SNR: {:g} dB, n = {}: inner hull ...", snr_db, n));
    const auto hull = ComputeInnerHull(set, CeroneExample::TrueParameters(), ParameterIndices(set, options.params),
                                       options.inner, {}, log);
    for (const auto& iv : hull.intervals)
      if (const auto paper = PaperTableInterval(iv.name, n); paper && iv.found)
        ratios.push_back({n, iv.name, iv.half_width(), paper->half_width()});
  }
  // Each table's own criterion too: the run may be stopped before the JSON that holds them is written.
  const SnrEvaluation evaluation{snr_db, MedianLogRatio(ratios), ratios};
  const std::vector<int> horizons = evaluation.horizons();
  std::string per_table;
  if (horizons.size() > 1) {
    for (int n : horizons)
      per_table += fmt::format("{}n = {}: {:.3f}", per_table.empty() ? " (" : ", ", n, evaluation.criterion_of(n));
    per_table += ")";
  }
  log(fmt::format("equivalent SNR: {:g} dB -> median log ratio {:.3f}{}", snr_db, evaluation.criterion, per_table));
  return ratios;
}

}  // namespace hw::cerone
