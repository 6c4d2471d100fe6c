#pragma once
// Guaranteed intervals of the exact feasible set D (one noise sequence for the whole record; paper 001,
// eqs. 8-11) inside a proven start box (the D^ss(n) engine's result, or the prior box).
//
// Stages, each in its own unit:
//   1. prune       (exact/branch_and_bound.hpp): halve the dynamics' box level by level; boxes whose lifted
//                  LP proves every equation residual positive (exact/box_evaluation.hpp) are dropped.
//   2. inner hull  (exact/inner_hull.hpp): points of D by local search, each re-checked by the membership LP.
//   3. bound       (exact/branch_and_bound.hpp): every endpoint refined best-first over the live boxes until it
//                  is within a target of the inner hull; then once more in the box the first sweep proved
//                  (tighter envelopes; gamma through beta/b once b has a sign).
//   4. check       the model-class assumption on the result: p(alpha, .) increasing over the data range.
// Jobs (a box's emptiness test, an endpoint's refinement) run on a JobExecutor (fork workers, MPI ranks) and
// are pure functions of their specs, so every executor gives the same numbers; a run directory keeps them.
//
// Assumptions every result states: the model class (bases, na, nb, properness), the noise bound per sample,
// the start box, and that the inverse output map p(alpha, w) = sum_j alpha_j phi_j(w) increases on the data
// range [min(y - dy), max(y + dy)] (paper 001 takes it invertible; alpha_1 = 1 fixes the sign).
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "exact/branch_and_bound.hpp"
#include "exact/inner_hull.hpp"
#include "sdp/job_executor.hpp"

namespace hw::exact {

// The inner hull's searches from the start only.
inline InnerHullOptions NoRestarts() {
  InnerHullOptions o;
  o.restarts = 0;
  return o;
}

struct ExactBoundsOptions {
  // The LP backend (exact/lp_solver.hpp). The interior point with CLP's fallback: at N = 1000 the same intervals
  // as CLP alone in a fifth of the time (docs/exact_set.md, "LP backends").
  std::string lp_solver = "ipm";
  BoxEvaluationOptions evaluation;
  PruneStop prune;
  ObjectiveSearchOptions search;
  // Bounding sweeps at most; each after the first starts in the box the previous proved. Sweeps stop early once
  // every interval is within target_ratio times its inner hull.
  int sweeps = 4;
  // Bound forms across D's thin directions too (exact/parameter_forms.hpp): over (a_1..a_na), halved beside the
  // a_i, and, as `forms` asks, over the b_j and the gammas.
  bool dynamics_forms = true;
  FormOptions forms;
  double target_ratio = 1.25;     // stop refining an endpoint once outer/inner width would be at most this
  // After the sweeps, the endpoints still short of the target get a closing pass with the LPs a sweep would have
  // given the others: up to this many times search.lp_budget each (1 = no closing pass).
  int short_endpoint_budget_cap = 4;
  bool inner_hull = true;
  InnerHullOptions inner = NoRestarts();  // restarts measured to cost 15x for no wider range (docs/exact_set.md)
  std::vector<std::string> parameters;  // intervals to compute; empty = all
  int threads = 0;                      // fork workers (0 = one per core); ignored when executor is set
  std::shared_ptr<sdp::JobExecutor> executor;
  std::string run_dir;                  // resumable job cache; empty = none
  bool IsValid(std::string* error) const;
};

enum class EndpointStatus { kGuaranteed, kConservative, kEmpty };
std::string ToString(EndpointStatus status);

struct ExactEndpoint {
  double value = 0.0;
  EndpointStatus status = EndpointStatus::kGuaranteed;  // kConservative: an edge of the start box, not an LP bound
  bool verified = true;   // every LP bound entering it is a safe bound (always, unless the box edge is the bound)
  double correction = 0.0;  // |value - the LP's floating-point value|
};

struct ExactInterval {
  std::string name;
  ExactEndpoint lower, upper;
  std::optional<std::pair<double, double>> inner;  // range over certified points of D
};

// The model-class assumption checked on the result: p(alpha, .) increases on the data range for every alpha of
// the final box (checked at the grid's intervals: the smallest difference p(g_{m+1}) - p(g_m) over the box).
struct AssumptionCheck {
  bool holds = false;
  double smallest_increase = 0.0;  // over the box and the grid (< 0: where it fails)
  double where_lo = 0.0, where_hi = 0.0;  // the grid interval of the smallest increase
  int grid_points = 0;
  nlohmann::json to_json() const;
};

struct ExactBoundsProgress {
  std::string phase;  // "prune", "inner hull", "bound (sweep k)"
  int done = 0, total = 0;
  std::string detail;  // e.g. "level 12, 3 boxes live, a1 in [1.79, 1.81]"
  double elapsed_seconds = 0.0;
};

struct ExactBoundsSummary {
  std::vector<std::string> parameter_names;
  std::vector<ExactInterval> intervals;
  ParamBox start_box;
  bool invalidated = false;                      // every box proven empty
  std::vector<nlohmann::json> certificates;      // of the pruned boxes when invalidated (box + certificate)
  int prune_levels = 0, boxes_evaluated = 0, boxes_pruned = 0, boxes_live = 0;
  int sweeps = 0;                                // bounding sweeps run (fewer than asked once all are within target)
  bool closing_pass = false;                     // the endpoints still short of the target had a pass of their own
  int lps = 0, lp_failures = 0, jobs = 0, jobs_from_cache = 0;
  int lp_rows = 0, lp_cols = 0;                  // of the whole-record LP
  long lp_nonzeros = 0;
  double prune_seconds = 0.0, inner_seconds = 0.0, bound_seconds = 0.0, wall_seconds = 0.0;
  int inner_points = 0;
  AssumptionCheck assumption;
  std::string executor;
  std::string lp_solver;       // the LP backend that ran (certificates do not depend on it)
  std::vector<ParameterForm> forms;  // the forms the bounding sweeps used
  bool worker_rank = false;
  nlohmann::json to_json() const;
};

ExactBoundsSummary ComputeExactBounds(const ExactBoundsOptions& options, const dss::HwStructure& structure,
                                      const dss::HwData& data, const ParamBox& start_box,
                                      const std::function<void(const ExactBoundsProgress&)>& progress = {});

// Whether an interval's outer/inner width is at most target_ratio (no inner hull: no).
bool WithinTarget(const ExactInterval& interval, double target_ratio);
bool AllWithinTarget(const std::vector<ExactInterval>& intervals, double target_ratio);
// Whether an endpoint of an interval beyond its target lies farther from its inner hull than (target_ratio - 1) / 2
// of the inner width (no inner hull: yes) — the end that keeps the interval from its target.
bool ShortOfTarget(const ExactInterval& interval, bool maximise, double target_ratio);
// The LP budget of an endpoint still short of its target in the closing pass: what a sweep would have given every
// endpoint, shared among the short ones — lp_budget times (endpoints / short ones), at most `cap` times — so the
// pass never spends more than a sweep's budget.
int ShortEndpointBudget(const std::vector<ExactInterval>& intervals, double target_ratio, int lp_budget, int cap);

// The assumption's statement, for --help, summaries and JSON.
std::string MonotoneAssumptionText();

}  // namespace hw::exact
