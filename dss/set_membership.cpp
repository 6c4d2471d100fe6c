#include "dss/set_membership.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "core/input_error.hpp"
#include "dss/box_contraction.hpp"
#include "dss/engine_setup.hpp"
#include "dss/job_function.hpp"
#include "dss/pipeline_state.hpp"
#include "dss/row_reduction.hpp"

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
std::string ProblemKey(const BoundsOptions& options, const EngineSettings& settings, const HwOuterSet& set,
                       nlohmann::json* meta) {
  *meta = {{"parameters", set.layout().names}, {"horizon", set.horizon()},
           {"cheap_pass", options.cheap_pass}, {"solver", options.solver}, {"backends", settings.backends},
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
void ReportOrthants(const HwOuterSet& set, const ScreenResult& screen, const PipelineState& state,
                    BoundsSummary& summary) {
  const std::vector<OrthantWork>& orthants = state.orthants;
  const PassOutcomes& full = state.full;
  summary.orthants_total = set.num_orthants();
  std::vector<std::optional<EmptinessCertificate>> certificate = screen.certificates;
  std::vector<OrthantStatus> status;
  for (const auto& c : certificate) status.push_back(c ? OrthantStatus::kEmpty : OrthantStatus::kUndecided);
  for (const auto& w : orthants) {
    if (w.empty()) certificate[w.index] = w.certificate;
    bool failed = false;
    for (int o : state.wanted_objectives)
      if (full.count({w.index, o}) && full.at({w.index, o}).status == JobStatus::kFailed) failed = true;
    status[w.index] = w.empty() ? OrthantStatus::kEmpty : failed ? OrthantStatus::kFailed : OrthantStatus::kSolved;
    summary.row_reduction.push_back({{"orthant", w.index}, {"per_step", w.reduction}});
    if (!w.empty() && w.box != set.box()) summary.orthant_boxes.push_back({w.index, w.box});
  }
  for (int l = 0; l < set.num_orthants(); ++l) {
    if (status[l] == OrthantStatus::kEmpty) ++summary.orthants_empty;
    else if (status[l] == OrthantStatus::kFailed) ++summary.orthants_failed;
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


BoundsSummary ComputeBounds(const BoundsOptions& options, const HwOuterSet& set,
                            const std::function<void(const BoundsProgress&)>& progress) {
  std::string error;
  if (!options.IsValid(&error)) throw InputError("bounds options: " + error);
  const auto t0 = Clock::now();
  if (!ValidOrder(options.order, set.horizon(), &error)) throw InputError(error);
  // The options, converted once into what the stages read.
  const EngineSettings settings = ToEngineSettings(options);
  const StageOptions stages = ToStageOptions(options, set.horizon());
  PipelineState state;
  const std::vector<int> wanted = WantedParameters(options, set);
  // Objectives: min and max of every wanted parameter (of every parameter when boxes are contracted).
  for (int k = 0; k < set.num_vars(); ++k)
    if (options.contraction_passes > 0 || std::find(wanted.begin(), wanted.end(), k) != wanted.end()) {
      state.objectives.push_back({k, -1});
      state.objectives.push_back({k, +1});
    }
  for (std::size_t o = 0; o < state.objectives.size(); ++o)
    if (std::find(wanted.begin(), wanted.end(), state.objectives[o].param) != wanted.end())
      state.wanted_objectives.push_back(static_cast<int>(o));

  const std::shared_ptr<sdp::JobExecutor> executor =
      options.executor ? options.executor : std::make_shared<sdp::ForkExecutor>(options.threads);
  const sdp::JobFunction job = MakeJobFunction(settings, set);
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
  const RunCache cache(options.run_dir, ProblemKey(options, settings, set, &meta), meta);
  EngineCounters counters;
  ProgressReporter reporter(progress);
  if (const auto line = cache.resume_line()) reporter.Message(*line);
  EngineContext ctx{settings, set, *executor, job, cache, counters, reporter};

  // 1. Screen orthants.
  const ScreenResult screen = ScreenOrthants(stages.screen, ctx);
  const int rows_per_orthant = set.num_orthants() > 0 ? static_cast<int>(set.data_constraints(0).size()) : 0;
  for (int l : screen.alive) {
    OrthantWork w;
    w.index = l;
    w.box = set.box();
    for (int r = 0; r < rows_per_orthant; ++r) w.rows.push_back(r);
    state.orthants.push_back(std::move(w));
  }
  // 2. Reduce rows.
  ReduceOrthantRows(ctx, state.orthants);
  // 3. Endpoints at the box edge, settled by feasible points.
  const EdgeWitnessResult edges = SettleEdgesByWitnesses(stages.edge_witness, ctx, state);
  // 4. Cheap pass (with box contraction when asked).
  const CheapPassResult cheap = RunCheapPass(stages.cheap, ctx, state);
  // 5. Full pass, in boxes contracted to the cheap bounds.
  if (stages.has_full_pass() && stages.contract_before_full_pass) ContractBeforeFullPass(ctx, state, stages.cheap.order);
  state.full = state.cheap;
  if (stages.has_full_pass()) RunFullPass(stages.full, ctx, state);
  // 6. Solve again, in contracted boxes, the endpoints that rest on a solve that stopped short.
  const RefinePassResult refined = RefineEndpoints(stages.stopped_short, ctx, state);
  // 6b. Solve every open endpoint again in the box of the full pass's own bounds (off by default).
  const RefinePassResult endpoints_refined = RefineEndpoints(stages.every_endpoint, ctx, state);
  // 7. Feasible points where the relaxations' moments point (the witnessed ranges; the bounds do not change).
  const MomentWitnessResult from_moments = FeasiblePointsFromMoments(stages.moment_witness, ctx, state);
  // 8. Aggregate.
  const AggregateResult agg = AggregateIntervals(stages.aggregate, set, state.objectives, wanted, state.cheap,
                                                 state.full, state.orthants);

  BoundsSummary summary;
  summary.intervals = agg.intervals;
  summary.bound_sources = agg.sources;
  std::vector<FeasiblePoint> feasible = edges.feasible_points;
  feasible.insert(feasible.end(), from_moments.feasible_points.begin(), from_moments.feasible_points.end());
  summary.feasible_points = ExtremeFeasiblePoints(state.objectives, feasible);
  AttachWitnessedRanges(set, summary.feasible_points, summary.intervals);
  summary.clipped_to_box = agg.clipped_to_box;
  summary.contraction_passes_run = cheap.contraction_passes_run;
  summary.refine_jobs = refined.jobs_run;
  summary.refine_tightened = refined.bounds_tightened;
  summary.endpoint_refine_jobs = endpoints_refined.jobs_run;
  summary.endpoint_refine_tightened = endpoints_refined.bounds_tightened;
  summary.order = options.order;
  summary.horizon = set.horizon();
  summary.solver = settings.backend(options.order);
  summary.solver_option = options.solver;
  summary.relaxation = RelaxationName(set, options.order, options.generation.block_order_cap);
  summary.executor = fmt::format("{} ({} workers)", executor->name(), executor->workers());
  summary.box = set.box();
  summary.parameter_names = set.layout().names;
  ReportOrthants(set, screen, state, summary);
  summary.edge_witness_solves = edges.local_solves;
  summary.edge_witness_seconds = edges.seconds;
  summary.moment_witness_jobs = from_moments.jobs;
  summary.moment_witness_found = static_cast<int>(from_moments.feasible_points.size());
  summary.moment_witness_seconds = from_moments.seconds;
  for (const auto& [key, r] : state.settled) summary.edge_witness_settled += r.status == JobStatus::kSolved ? 1 : 0;
  CopyJobCounters(counters, summary);
  summary.wall_seconds = std::chrono::duration<double>(Clock::now() - t0).count();
  return summary;
}

namespace {

BoundsRun RunWith(const BoundsOptions& options) {
  return [&options](const HwOuterSet& set, const ProgressSink& progress) { return ComputeBounds(options, set, progress); };
}

}  // namespace

BoundsSummary ComputeBoundsInPieces(const BoundsOptions& options, const HwOuterSet& set,
                                    const std::vector<BoxCut>& cuts,
                                    const std::function<void(const BoundsProgress&)>& progress) {
  return BoundsInPieces(RunWith(options), set, cuts, progress);
}

BoundsSummary ComputeBoundsWithAutoSplit(const BoundsOptions& options, const HwOuterSet& set,
                                         const std::vector<BoxCut>& cuts, const AutoSplitOptions& auto_split,
                                         const std::function<void(const BoundsProgress&)>& progress) {
  return BoundsWithAutoSplit(RunWith(options), options.executor ? options.executor->name() : "", set, cuts,
                             auto_split, progress);
}

}  // namespace hw::dss
