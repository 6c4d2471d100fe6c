#include "dss/set_membership.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "core/csv_table.hpp"
#include "dss/aggregate.hpp"
#include "dss/bound_jobs.hpp"
#include "dss/box_contraction.hpp"
#include "dss/cheap_pass.hpp"
#include "dss/edge_witness.hpp"
#include "dss/full_pass.hpp"
#include "dss/moment_witness.hpp"
#include "dss/orthant_screen.hpp"
#include "dss/refine_pass.hpp"
#include "dss/row_reduction.hpp"
#include "sdp/sdp_solver.hpp"

namespace hw::dss {
namespace {

using Clock = std::chrono::steady_clock;

std::string sign_text(const HwOuterSet& set, int l) {
  std::string s;
  const auto signs = set.orthant_signs(l);
  for (std::size_t k = 0; k < signs.size(); ++k)
    s += fmt::format("{}{}{}", k ? " " : "", set.sign_names()[k], signs[k] > 0 ? "+" : "-");
  return s;
}

// The engine-wide SDP settings every job uses (see the comments), applied to a copy of the caller's options.
BoundsOptions EngineOptions(const BoundsOptions& options) {
  BoundsOptions opts = options;
  // In scaled coordinates every feasible moment vector has |y_alpha| <= 1, so a multiplier X >= 0 with
  // sum_i |F_i . X| < F_0 . X already proves emptiness; 0.5 leaves a margin.
  opts.generation.sdp.infeasibility_tolerance = std::max(opts.generation.sdp.infeasibility_tolerance, 0.5);
  // Endpoints come from the dual side, whose validity needs dual feasibility, not a small gap: accept
  // near-optimal stops up to 1e-5 (the gap costs at most that much tightness on the scaled parameters).
  opts.generation.sdp.acceptable_gap = std::max(opts.generation.sdp.acceptable_gap, 1e-5);
  // The engine's own fallbacks (the other backend, then the verified bounds of the rounds) follow a failed
  // round, so a second SDPA attempt with other parameters would only add a full solve to each failing round.
  opts.generation.sdp.retry_with_default_parameters = false;
  return opts;
}

// The backend of every relaxation order (index 0: order 1), whatever the run's order.
std::vector<std::string> BackendsByOrder(const BoundsOptions& options) {
  std::vector<std::string> backends;
  for (int d = 1; d <= kMaxOrder; ++d)
    backends.push_back(SolverForOrder(options.solver, d, options.generation.block_order_cap));
  return backends;
}

// "order d", or the mixed relaxation's name when the cap lowers some data row's localizing order d - ceil(deg / 2).
std::string RelaxationName(const HwOuterSet& set, int order, int block_order_cap) {
  bool capped = false;
  if (block_order_cap >= 0 && set.num_orthants() > 0)
    for (const auto& g : set.data_constraints(0)) capped = capped || order - (g.g.degree() + 1) / 2 > block_order_cap;
  if (!capped) return fmt::format("order {}", order);
  return fmt::format("order {} with data-row blocks of localizing order <= {} (mixed: between the orders)", order,
                     block_order_cap);
}

// Everything that changes the numbers, hashed into the run directory's name. Not the run's order: a job's name
// carries the relaxation order it solves, and the stages before it (screen, reduction, feasible points) do not
// depend on it, so runs of several orders share one directory and an order-3 run reads back the order-2 jobs
// of an order-2 run (its cheap pass). Nor contract_before_full_pass: a job in a contracted box has the box's hash
// in its name.
std::string ProblemKey(const BoundsOptions& options, const HwOuterSet& set, nlohmann::json* meta) {
  *meta = {{"parameters", set.layout().names}, {"horizon", set.horizon()},
           {"cheap_pass", options.cheap_pass}, {"solver", options.solver}, {"backends", BackendsByOrder(options)},
           {"box", set.box()},
           {"violation_tolerance", options.generation.violation_tolerance},
           {"gap_tolerance", options.generation.sdp.gap_tolerance}, {"verify", options.generation.verify.enabled},
           {"linear_rows_first", options.generation.linear_rows_first},
           {"add_per_round", options.generation.add_per_round}, {"max_rounds", options.generation.max_rounds},
           {"retry_undecided_rounds", options.generation.retry_undecided_rounds},
           {"row_reduction", options.reduction.enabled},
           {"contraction_passes", options.contraction_passes},
           {"contraction_min_shrink", options.contraction_min_shrink},
           {"contraction_max_rounds", options.contraction_max_rounds},
           {"stop_beyond_witnesses", options.edge_witness.stop_beyond_witnesses},
           {"block_order_cap", options.generation.block_order_cap}};
  uint64_t h = 1469598103934665603ull;
  auto mix = [&h](const std::string& t) {
    for (unsigned char c : t) h = (h ^ c) * 1099511628211ull;
  };
  mix(meta->dump());
  if (set.num_orthants() > 0)
    for (const auto& c : set.data_constraints(0)) mix(c.g.to_string());
  return fmt::format("{:016x}", h);
}

// The parameters whose intervals are wanted (all when none are named).
std::vector<int> WantedParameters(const BoundsOptions& options, const HwOuterSet& set) {
  const auto& names = set.layout().names;
  for (const auto& name : options.parameters)
    if (std::find(names.begin(), names.end(), name) == names.end()) {
      std::string all;
      for (const auto& nm : names) all += (all.empty() ? "" : ", ") + nm;
      throw InputError(fmt::format("no parameter '{}'; the parameters are: {}", name, all));
    }
  std::vector<int> wanted;
  for (int k = 0; k < set.num_vars(); ++k)
    if (options.parameters.empty() ||
        std::find(options.parameters.begin(), options.parameters.end(), names[k]) != options.parameters.end())
      wanted.push_back(k);
  return wanted;
}

// Sets *error (when given) and returns false: the tail of every IsValid-style check below.
bool Fail(std::string* error, std::string message) {
  if (error) *error = std::move(message);
  return false;
}

// Each interval's range over the feasible points (ParameterInterval::witnessed_lower/upper).
void AttachWitnessedRanges(const HwOuterSet& set, const std::vector<FeasiblePoint>& points,
                           std::vector<ParameterInterval>& intervals) {
  const auto& names = set.layout().names;
  for (auto& iv : intervals) {
    const std::size_t k = std::find(names.begin(), names.end(), iv.name) - names.begin();
    for (const auto& p : points) {
      if (k >= p.point.size()) continue;
      iv.witnessed_lower = std::min(iv.witnessed_lower.value_or(p.point[k]), p.point[k]);
      iv.witnessed_upper = std::max(iv.witnessed_upper.value_or(p.point[k]), p.point[k]);
    }
  }
}

// Each orthant's status and certificate (screen, then the pipeline's passes), its row reduction and contracted box.
void ReportOrthants(const HwOuterSet& set, const ScreenResult& screen, const std::vector<OrthantWork>& orthants,
                    const PassOutcomes& full, const std::vector<int>& wanted_objectives, BoundsSummary& summary) {
  summary.orthants_total = set.num_orthants();
  std::vector<std::string> status = screen.status;
  std::vector<std::optional<EmptinessCertificate>> certificate = screen.certificates;
  for (const auto& w : orthants) {
    if (w.empty()) certificate[w.index] = w.certificate;
    bool failed = false;
    for (int o : wanted_objectives)
      if (full.count({w.index, o}) && full.at({w.index, o}).status == "failed") failed = true;
    status[w.index] = w.empty() ? w.status : failed ? "failed (conservative fallback)" : "solved";
    summary.row_reduction.push_back({{"orthant", w.index}, {"per_step", w.reduction}});
    if (!w.empty() && w.box != set.box()) summary.orthant_boxes.push_back({w.index, w.box});
  }
  for (int l = 0; l < set.num_orthants(); ++l) {
    if (status[l].rfind("empty", 0) == 0) ++summary.orthants_empty;
    else if (status[l].rfind("failed", 0) == 0) ++summary.orthants_failed;
    else ++summary.orthants_solved;
    summary.orthants.push_back({l, sign_text(set, l), status[l], certificate[l]});
  }
}

// The job counts and times of the run (cached jobs excluded from the times).
void CopyJobCounters(EngineCounters counters, BoundsSummary& summary) {
  summary.sdp_jobs = counters.sdp_jobs;
  summary.sdp_solves = counters.sdp_solves;
  summary.jobs_from_cache = counters.jobs_from_cache;
  summary.jobs_stopped_beyond_witness = counters.jobs_stopped_beyond_witness;
  summary.jobs_settled_by_sign = counters.jobs_settled_by_sign;
  summary.solve_seconds = counters.solve_seconds;
  summary.verify_seconds = counters.verify_seconds;
  summary.largest_moments = counters.largest_moments;
  summary.largest_blocks = counters.largest_blocks;
  std::sort(counters.solve_times.begin(), counters.solve_times.end());
  if (!counters.solve_times.empty()) summary.median_solve_seconds = counters.solve_times[counters.solve_times.size() / 2];
}

}  // namespace

bool ValidOrder(int order, int horizon, std::string* error) {
  const int minimal = MinimalOrder(horizon);
  if (order < minimal)
    return Fail(error, fmt::format("order {} is below the minimal order ceil((n+1)/2) = {} of horizon {}; leave the "
                                   "order unset for the minimal order",
                                   order, minimal, horizon));
  if (order > kMaxOrder)
    return Fail(error, fmt::format("order {} is above the largest relaxation order {}", order, kMaxOrder));
  return true;
}

bool ValidThreads(int threads, std::string* error) {
  if (threads >= 0) return true;
  return Fail(error, fmt::format("threads {} is negative; give 0 (one job per core) or the number of jobs", threads));
}

bool ValidContractionPasses(int passes, std::string* error) {
  if (passes >= 0 && passes <= 10) return true;
  return Fail(error, fmt::format("contraction_passes {} is out of range 0..10 (0 = no box contraction)", passes));
}

bool ValidStoppedShortRefinements(int refinements, std::string* error) {
  if (refinements >= 0) return true;
  return Fail(error, fmt::format("stopped_short_refinements {} is negative; give 0 (never) or more", refinements));
}

bool ValidEndpointRefinements(int refinements, std::string* error) {
  if (refinements >= 0 && refinements <= kMaxEndpointRefinements) return true;
  return Fail(error, fmt::format("endpoint_refinements {} is out of range 0..{} (0 = never)", refinements,
                                 kMaxEndpointRefinements));
}

bool ValidBoundsSolver(const std::string& name, std::string* error) {
  if (name == "auto") return true;
  if (sdp::ValidSolverName(name, nullptr)) return true;
  return Fail(error, fmt::format("solver '{}' unknown; expected auto (a backend per relaxation), {}", name,
                                 fmt::join(sdp::AvailableSolvers(), ", ")));
}

std::string SolverForOrder(const std::string& name, int /*order*/, int /*block_order_cap*/) {
  return name == "auto" ? "csdp" : name;
}

bool BoundsOptions::IsValid(std::string* error) const {
  auto fail = [&](std::string m) { return Fail(error, std::move(m)); };
  if (order < 1 || order > kMaxOrder) return fail(fmt::format("order {} is out of range 1..{}", order, kMaxOrder));
  if (!ValidThreads(threads, error) || !ValidContractionPasses(contraction_passes, error)) return false;
  if (contraction_max_rounds < 1) return fail("contraction_max_rounds must be >= 1");
  if (!ValidStoppedShortRefinements(stopped_short_refinements, error)) return false;
  if (!ValidEndpointRefinements(endpoint_refinements, error)) return false;
  if (!(contraction_min_shrink >= 0 && contraction_min_shrink < 1)) return fail("contraction_min_shrink must lie in [0, 1)");
  if (!ValidBoundsSolver(solver, error)) return false;
  if (!reduction.IsValid(error)) return false;
  if (!edge_witness.IsValid(error)) return false;
  return generation.IsValid(error);
}

std::string EmptinessCertificate::status() const {
  if (kind == "lp") return "empty (LP)";
  if (kind == "pieces") return order > 0 ? fmt::format("empty in every piece (up to order {})", order) : "empty in every piece (LP)";
  return fmt::format("empty (order {}{}{})", order, contracted_box ? ", contracted box" : "",
                     kind == "crossed bounds" ? ", bounds cross" : "");
}

nlohmann::json EmptinessCertificate::to_json() const {
  return {{"kind", kind}, {"order", kind == "lp" ? nlohmann::json(nullptr) : nlohmann::json(order)},
          {"contracted_box", contracted_box}, {"verified", verified}};
}

bool BoundsSummary::invalidated() const {
  if (orthants_total == 0 || orthants_empty != orthants_total) return false;
  for (const auto& o : orthants)
    if (o.status.rfind("empty", 0) != 0) return false;
  return true;
}

bool BoundsSummary::all_guaranteed() const {
  if (invalidated()) return true;  // every orthant proven empty: no endpoint to guarantee
  for (const auto& iv : intervals)
    for (const Endpoint* e : {&iv.lower, &iv.upper})
      // A floating-point bound that verification could not prove is not called guaranteed.
      if (e->status != "guaranteed" || e->verification == "unverified") return false;
  return true;
}

nlohmann::json BoundsSummary::to_json() const {
  nlohmann::json j;
  j["order"] = order;
  j["horizon"] = horizon;
  j["solver"] = solver;
  j["solver_option"] = solver_option;
  j["relaxation"] = relaxation;
  j["executor"] = executor;
  nlohmann::json box_j = nlohmann::json::array();
  for (std::size_t i = 0; i < box.size(); ++i)
    box_j.push_back({{"parameter", parameter_names[i]}, {"lo", box[i].first}, {"hi", box[i].second}});
  j["prior_box"] = box_j;
  j["prior_box_note"] = "intervals are guaranteed for parameters inside this box (a prior assumption)";
  const bool none = invalidated();
  j["invalidated"] = none;
  if (none)
    j["verdict"] = "no parameter in the prior box explains the data within the noise bound: the model class "
                   "(orders, bases) or the noise bound is wrong (every orthant is proven empty; see `hwbounds diagnose`)";
  auto ep = [none](const Endpoint& e) {
    return nlohmann::json{{"value", none ? nlohmann::json(nullptr) : nlohmann::json(e.value)}, {"status", e.status}, {"note", e.note}, {"orthant", e.orthant},
                          {"tight", e.tight}, {"verification", e.verification}, {"correction", e.correction}};
  };
  auto witnessed = [](const ParameterInterval& iv) {
    if (!iv.witnessed_lower || !iv.witnessed_upper) return nlohmann::json(nullptr);
    return nlohmann::json{{"lower", *iv.witnessed_lower}, {"upper", *iv.witnessed_upper}};
  };
  for (const auto& iv : intervals)
    j["intervals"].push_back({{"parameter", iv.name}, {"lower", ep(iv.lower)}, {"upper", ep(iv.upper)},
                              {"half_width", none ? nlohmann::json(nullptr) : nlohmann::json(iv.half_width())},
                              {"witnessed", witnessed(iv)}});
  j["feasible_points"] = nlohmann::json::array();
  for (const auto& p : feasible_points) {
    nlohmann::json point;
    for (std::size_t i = 0; i < p.point.size() && i < parameter_names.size(); ++i) point[parameter_names[i]] = p.point[i];
    j["feasible_points"].push_back(
        {{"orthant", p.orthant}, {"point", point}, {"certified_min_slack", p.certified_min_slack}});
  }
  for (const auto& o : orthants)
    j["orthants"].push_back({{"index", o.index}, {"signs", o.signs}, {"status", o.status},
                             {"certificate", o.certificate ? o.certificate->to_json() : nlohmann::json(nullptr)}});
  j["counts"] = {{"orthants_total", orthants_total}, {"orthants_proven_empty", orthants_empty},
                 {"orthants_solved", orthants_solved}, {"orthants_failed", orthants_failed},
                 {"sdp_jobs", sdp_jobs}, {"sdp_solves", sdp_solves}, {"jobs_from_cache", jobs_from_cache},
                 {"jobs_stopped_beyond_witness", jobs_stopped_beyond_witness},
                 {"jobs_settled_by_sign", jobs_settled_by_sign},
                 {"edge_witness_settled", edge_witness_settled}, {"edge_witness_solves", edge_witness_solves},
                 {"moment_witness_jobs", moment_witness_jobs}, {"moment_witness_found", moment_witness_found}};
  j["timing"] = {{"wall_seconds", wall_seconds}, {"median_solve_seconds", median_solve_seconds},
                 {"solve_seconds", solve_seconds}, {"verify_seconds", verify_seconds},
                 {"edge_witness_seconds", edge_witness_seconds}, {"moment_witness_seconds", moment_witness_seconds}};
  j["largest_sdp"] = {{"moments", largest_moments}, {"blocks", largest_blocks}};
  j["all_guaranteed"] = all_guaranteed();
  j["contraction_passes_run"] = contraction_passes_run;
  j["stopped_short_refined"] = {{"jobs", refine_jobs}, {"tightened", refine_tightened}};
  j["endpoints_refined"] = {{"jobs", endpoint_refine_jobs}, {"tightened", endpoint_refine_tightened}};
  j["row_reduction"] = row_reduction;
  j["bound_sources"] = bound_sources;
  j["clipped_to_prior_box"] = clipped_to_box;
  if (!pieces.empty()) j["pieces"] = pieces;
  if (!auto_split.is_null()) j["auto_split"] = auto_split;
  for (const auto& [l, b] : orthant_boxes) {
    nlohmann::json bj = nlohmann::json::array();
    for (std::size_t i = 0; i < b.size(); ++i)
      bj.push_back({{"parameter", parameter_names[i]}, {"lo", b[i].first}, {"hi", b[i].second}});
    j["contracted_boxes"].push_back({{"orthant", l}, {"box", bj}});
  }
  return j;
}

BoundsSummary ComputeBounds(const BoundsOptions& caller_options, const HwOuterSet& set,
                            const std::function<void(const BoundsProgress&)>& progress) {
  std::string error;
  if (!caller_options.IsValid(&error)) throw InputError("bounds options: " + error);
  const BoundsOptions options = EngineOptions(caller_options);
  const auto t0 = Clock::now();
  // Minimal order from the constraint degrees: Remark 3, ceil((n + 1) / 2), and >= 1 for the box.
  const int min_order = MinimalOrder(set.horizon());
  if (!ValidOrder(options.order, set.horizon(), &error)) throw InputError(error);
  // Order 1 (Shor) returns the box edges for these problems, so the cheap order is at least 2; with nothing
  // cheaper than the target order there is no separate cheap pass.
  const int cheap_order = options.cheap_pass ? std::min(options.order, std::max(min_order, 2)) : options.order;
  const std::vector<int> wanted = WantedParameters(options, set);
  // Objectives: min and max of every wanted parameter (of every parameter when boxes are contracted).
  std::vector<Objective> objectives;
  for (int k = 0; k < set.num_vars(); ++k)
    if (options.contraction_passes > 0 || std::find(wanted.begin(), wanted.end(), k) != wanted.end()) {
      objectives.push_back({k, -1});
      objectives.push_back({k, +1});
    }
  std::vector<int> wanted_objectives;
  for (std::size_t o = 0; o < objectives.size(); ++o)
    if (std::find(wanted.begin(), wanted.end(), objectives[o].param) != wanted.end())
      wanted_objectives.push_back(static_cast<int>(o));

  const std::shared_ptr<sdp::JobExecutor> executor =
      options.executor ? options.executor : std::make_shared<sdp::ForkExecutor>(options.threads);
  const sdp::JobFunction job = MakeJobFunction(options, set);
  // Worker ranks (MPI) answer jobs until the coordinator ends the session; they report nothing themselves.
  if (!executor->is_coordinator()) {
    executor->Serve(job);
    BoundsSummary worker;
    worker.worker_rank = true;
    return worker;
  }
  struct SessionEnd {  // also when the coordinator throws, so that no worker is left waiting
    sdp::JobExecutor& e;
    ~SessionEnd() { e.EndSession(); }
  } session_end{*executor};

  nlohmann::json meta;
  const RunCache cache(options.run_dir, ProblemKey(options, set, &meta), meta);
  EngineCounters counters;
  ProgressReporter reporter(progress);
  if (const auto line = cache.resume_line()) reporter.Message(*line);
  EngineContext ctx{options, set, *executor, job, cache, counters, reporter};

  // 1. Screen orthants.
  const ScreenResult screen = ScreenOrthants(ScreenOptions{options.lp_screen}, ctx);
  std::vector<OrthantWork> orthants;
  const int rows_per_orthant = set.num_orthants() > 0 ? static_cast<int>(set.data_constraints(0).size()) : 0;
  for (int l : screen.alive) {
    OrthantWork w;
    w.index = l;
    w.box = set.box();
    for (int r = 0; r < rows_per_orthant; ++r) w.rows.push_back(r);
    orthants.push_back(std::move(w));
  }
  // 2. Reduce rows.
  ReduceOrthantRows(ctx, orthants);
  // 3. Endpoints at the box edge, settled by feasible points.
  EdgeWitnessOptions edge_options = options.edge_witness;
  edge_options.enabled = edge_options.enabled && options.order >= edge_options.min_order;
  const EdgeWitnessResult edges = SettleEdgesByWitnesses(edge_options, ctx, objectives, orthants);
  // 4. Cheap pass (with box contraction when asked).
  CheapPassOptions cheap_options{cheap_order, options.contraction_passes, options.contraction_min_shrink,
                                 options.contraction_max_rounds};
  const CheapPassResult cheap = RunCheapPass(cheap_options, ctx, objectives, edges.settled, edges.witnessed, orthants);
  // 5. Full pass, in boxes contracted to the cheap bounds.
  PassOutcomes cheap_outcomes = cheap.outcomes;
  if (options.order > cheap_order && options.contract_before_full_pass)
    cheap_outcomes = ContractBeforeFullPass(ctx, objectives, cheap.outcomes, orthants, cheap_order);
  PassOutcomes full = cheap_outcomes;
  if (options.order > cheap_order)
    full = RunFullPass(FullPassOptions{options.order, cheap_order}, ctx, objectives, wanted_objectives, cheap_outcomes,
                       edges.settled, edges.witnessed, orthants);
  // 6. Solve again, in contracted boxes, the endpoints that rest on a solve that stopped short.
  const RefinePassResult refined =
      RefineEndpoints(RefinePassOptions{options.order, options.stopped_short_refinements, false}, ctx, objectives,
                      wanted_objectives, full, edges.witnessed, orthants);
  full = refined.outcomes;
  // 6b. Solve every open endpoint again in the box of the full pass's own bounds (off by default).
  const RefinePassResult endpoints_refined =
      RefineEndpoints(RefinePassOptions{options.order, options.endpoint_refinements, true}, ctx, objectives,
                      wanted_objectives, full, edges.witnessed, orthants);
  full = endpoints_refined.outcomes;
  // 7. Feasible points where the relaxations' moments point (the witnessed ranges; the bounds do not change). Not
  // below the edge-witness stage's order: there the SDP jobs cost less than the local searches.
  const MomentWitnessResult from_moments = FeasiblePointsFromMoments(
      MomentWitnessOptions{options.moment_witnesses && options.order >= options.edge_witness.min_order, options.order},
      ctx, objectives, wanted_objectives, full, orthants);
  // 8. Aggregate.
  const AggregateResult agg = AggregateIntervals(
      AggregateOptions{options.generation.verify.enabled, options.order, cheap_order}, set, objectives, wanted,
      cheap_outcomes, full, orthants);

  BoundsSummary summary;
  summary.intervals = agg.intervals;
  summary.bound_sources = agg.sources;
  std::vector<FeasiblePoint> feasible = edges.feasible_points;
  feasible.insert(feasible.end(), from_moments.feasible_points.begin(), from_moments.feasible_points.end());
  summary.feasible_points = ExtremeFeasiblePoints(objectives, feasible);
  AttachWitnessedRanges(set, summary.feasible_points, summary.intervals);
  summary.clipped_to_box = agg.clipped_to_box;
  summary.contraction_passes_run = cheap.contraction_passes_run;
  summary.refine_jobs = refined.jobs_run;
  summary.refine_tightened = refined.bounds_tightened;
  summary.endpoint_refine_jobs = endpoints_refined.jobs_run;
  summary.endpoint_refine_tightened = endpoints_refined.bounds_tightened;
  summary.order = options.order;
  summary.horizon = set.horizon();
  summary.solver = SolverForOrder(options.solver, options.order, options.generation.block_order_cap);
  summary.solver_option = options.solver;
  summary.relaxation = RelaxationName(set, options.order, options.generation.block_order_cap);
  summary.executor = fmt::format("{} ({} workers)", executor->name(), executor->workers());
  summary.box = set.box();
  summary.parameter_names = set.layout().names;
  ReportOrthants(set, screen, orthants, full, wanted_objectives, summary);
  summary.edge_witness_solves = edges.local_solves;
  summary.edge_witness_seconds = edges.seconds;
  summary.moment_witness_jobs = from_moments.jobs;
  summary.moment_witness_found = static_cast<int>(from_moments.feasible_points.size());
  summary.moment_witness_seconds = from_moments.seconds;
  for (const auto& [key, r] : edges.settled) summary.edge_witness_settled += r.status == "solved" ? 1 : 0;
  CopyJobCounters(counters, summary);
  summary.wall_seconds = std::chrono::duration<double>(Clock::now() - t0).count();
  return summary;
}

}  // namespace hw::dss
