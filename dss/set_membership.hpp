#pragma once
// Guaranteed parameter intervals of a Hammerstein–Wiener model over D^ss(n) (paper 001, eqs. 22-33).
//
// The engine is a pipeline of stages, each in its own file (docs/setmembership.md, "How the bounds are computed"):
//  1. screen orthants   (dss/orthant_screen.hpp): an LP per sign orthant; infeasible (verified) => empty.
//  2. reduce rows       (dss/row_reduction.hpp):  drop data rows implied by the others (exact at any order).
//  3. edge witnesses    (dss/edge_witness.hpp):   endpoints at the prior box edge settled by feasible points.
//  4. cheap pass        (dss/cheap_pass.hpp):     every objective of every live orthant at the minimal order.
//  5. full pass         (dss/full_pass.hpp):      the wanted objectives at order delta, skipping orthants
//                                                 whose cheap bound cannot move the interval (Property 3).
//  6. refine            (dss/refine_pass.hpp):    endpoints of solves that stopped short, in contracted boxes.
//  7. moment witnesses  (dss/moment_witness.hpp): feasible points where the relaxations' moments point.
//  8. aggregate         (dss/aggregate.hpp):      min/max over orthants, fallbacks, the prior box.
// Every job (dss/bound_jobs.hpp) solves its relaxation by constraint generation over the kept rows
// (pop/constraint_generation.hpp): rows enter as scalar moment constraints and get their localizing block
// when violated; every round's multiplier yields a verified bound, so a solve that stops short still bounds.
// Guarantees: every reported endpoint is a valid bound of D^ss(n) intersected with the prior box. A failed
// solve never disappears: the endpoint falls back to the same orthant's cheap-order bound, or to the box edge,
// and is marked "conservative"; an orthant is discarded only on a verified certificate.
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "dss/edge_witness_options.hpp"
#include "dss/hw_outer_set.hpp"
#include "dss/row_reduction_options.hpp"
#include "pop/constraint_generation.hpp"
#include "sdp/job_executor.hpp"

namespace hw::dss {

struct BoundsOptions {
  int order = 3;                 // delta of the reported intervals
  bool cheap_pass = true;        // solve the minimal order first to skip objectives (recommended)
  bool lp_screen = true;
  // "auto" (the backend per relaxation, SolverForOrder), "csdp", "sdpa" or "dsdp".
  std::string solver = "auto";
  // Local parallel jobs. CSDP and SDPA are not thread-safe, so jobs run in forked worker processes
  // (sdp::ForkExecutor); 0 = one per core. Ignored when `executor` is set.
  int threads = 0;
  // Where jobs run (sdp/job_executor.hpp): null = ForkExecutor(threads); sdp::MpiExecutor for MPI runs.
  std::shared_ptr<sdp::JobExecutor> executor;
  std::string run_dir;           // resumable cache; empty = none
  std::vector<std::string> parameters;  // intervals to compute (names); empty = every parameter
  // Box contraction (bound tightening). The cheap-order bounds of EVERY parameter in an orthant form a box
  // that contains the orthant's part of D^ss(n) inside the prior box, so relaxations in that smaller box bound
  // the same set: they stay valid, are at least as tight, and are far better conditioned (a thin set in a wide
  // box makes the moment matrices nearly singular; docs/setmembership_scale.md). After the first cheap pass,
  // up to `contraction_passes` more cheap passes run in the contracted boxes while some side still moves by
  // more than `contraction_min_shrink` of its width; the full-order pass runs in the last boxes. Only
  // verified bounds contract a box (or any solved bound with verification off). 0 = off (the default: on the
  // paper's example the capped passes contracted too little to pay for themselves; docs/setmembership_scale.md).
  int contraction_passes = 0;
  double contraction_min_shrink = 0.05;
  // Before a full pass above the cheap order, every orthant's box shrinks to its cheap-order bounds (no extra
  // solves: the cheap pass has them) and its rows are reduced again in the new box; the order-delta jobs then
  // run in that box. On the paper's example at 45 dB the cheap bounds are a few hundredths to a few units wide
  // in a box of width 20 (docs/setmembership_scale.md).
  bool contract_before_full_pass = true;
  // Constraint-generation rounds of a job in a contraction pass (every pass but the last): a subset of the
  // data inequalities already gives a valid bound, and the prior box's ill-conditioned LMIs are kept small.
  // The last cheap pass always runs to the full relaxation (generation.max_rounds).
  int contraction_max_rounds = 4;
  // After the last pass, an endpoint whose bound is the verified last iterate of a solve that stopped short (CSDP
  // "partial success", SDPA pFEAS) is solved again in its orthant's box contracted to that pass's verified bounds,
  // up to this many times (dss/refine_pass.hpp); the tighter bound is kept. 0 = off.
  int stopped_short_refinements = 1;
  // Then every endpoint that no certified feasible point reaches, finished or not, is solved again the same way,
  // up to this many times (dss/refine_pass.hpp): the full pass started in boxes contracted to the cheap order's
  // bounds, the refinement runs in boxes contracted to its own. 0 = off (costs one full-order job per endpoint).
  int endpoint_refinements = 0;
  pop::ConstraintGenerationOptions generation;  // its order is set per pass
  RowReductionOptions reduction;           // exact reduction of the data rows (stage 2)
  EdgeWitnessOptions edge_witness;         // endpoints settled by feasible points at the box edge (stage 3)
  // After the last pass, a local search from every solved job's first moments (dss/moment_witness.hpp): more
  // certified feasible points, so the witnessed ranges show how close each endpoint is to the exact interval.
  bool moment_witnesses = true;
  // Progress lines from inside jobs (one per constraint-generation round: working set, status, bound so far).
  // Called in the process that runs the job (a forked worker or an MPI rank); null = silent.
  std::function<void(const std::string&)> round_log;
  bool IsValid(std::string* error) const;
};

struct Endpoint {
  double value = 0.0;
  std::string status = "unknown";  // "guaranteed", "conservative" (fallback used), "empty" (no orthant left)
  std::string note;
  int orthant = -1;                // orthant attaining the endpoint
  bool tight = false;              // equals the full relaxation's bound (constraint generation converged)
  // "verified": every orthant bound entering the value was verified rigorously (sdp/verified_bound.hpp);
  // "unverified": at least one is the solver's floating-point bound; "off": verification disabled.
  std::string verification = "off";
  double correction = 0.0;         // |value - the same endpoint from the solvers' floating-point bounds|
};

struct ParameterInterval {
  std::string name;
  Endpoint lower, upper;
  // The range of the parameter over the certified feasible points the engine found (BoundsSummary::
  // feasible_points): the exact interval of D^ss(n) contains it, so [lower, witnessed_lower] and
  // [witnessed_upper, upper] bound what the relaxation may still overestimate. Absent without such points.
  std::optional<double> witnessed_lower, witnessed_upper;
  double half_width() const { return 0.5 * (upper.value - lower.value); }
};

// How a sign orthant was proven empty.
struct EmptinessCertificate {
  // "lp": the LP screen is infeasible; "relaxation": the relaxation of order `order` is infeasible;
  // "crossed bounds": the rigorous lower and upper bounds of a parameter at order `order` cross;
  // "pieces": empty in every piece of a split box (dss/box_split.hpp), `order` the highest order used there.
  std::string kind;
  int order = 0;                // relaxation order (0 for the LP screen)
  bool contracted_box = false;  // proven in the orthant's contracted box, which holds all its points of the prior box
  bool verified = false;        // checked in interval arithmetic; false: the solver's floating-point certificate
  std::string status() const;   // the orthant's status: "empty (LP)", "empty (order 2, contracted box)", ...
  nlohmann::json to_json() const;
};

struct OrthantReport {
  int index = 0;
  std::string signs;    // e.g. "alpha2+ alpha3+ Q1_1+ ..."
  std::string status;   // "empty (LP)", "empty (order k)", "solved", "failed (conservative)"
  std::optional<EmptinessCertificate> certificate;  // of an empty orthant
};

struct BoundsProgress {
  std::string phase;   // with done = total = -1: a one-off message (e.g. "resuming: ...")
  int done = 0, total = 0;  // of the jobs still to run in this phase (jobs read from the run cache excluded)
  int from_cache = 0;       // jobs of this phase read from the run cache so far
  double elapsed_seconds = 0.0, eta_seconds = 0.0;
};

struct BoundsSummary {
  std::vector<ParameterInterval> intervals;
  std::vector<OrthantReport> orthants;
  int orthants_total = 0, orthants_empty = 0, orthants_solved = 0, orthants_failed = 0;
  int sdp_jobs = 0;           // relaxation jobs run (cached ones excluded)
  int sdp_solves = 0;         // SDP solves including constraint-generation rounds
  int jobs_from_cache = 0;
  int jobs_stopped_beyond_witness = 0;  // ended early: their bound passed a certified feasible point's value
  int jobs_settled_by_sign = 0;  // not run: the orthant's sign constraints bound them beyond such a value
  int edge_witness_settled = 0;  // (orthant, objective) pairs settled by a feasible point at the box edge
  int edge_witness_solves = 0;   // local optimisations run to find them
  double edge_witness_seconds = 0.0;
  int moment_witness_jobs = 0;    // local searches started from the relaxations' first moments
  int moment_witness_found = 0;   // of them, certified feasible points
  double moment_witness_seconds = 0.0;
  double median_solve_seconds = 0.0;
  double solve_seconds = 0.0, verify_seconds = 0.0;  // totals over the jobs run (cache excluded); verify incl. re-solves
  std::size_t largest_moments = 0, largest_blocks = 0;
  double wall_seconds = 0.0;
  int order = 0, horizon = 0;
  std::string solver;          // the backend of the reported order's relaxations
  std::string solver_option;   // as asked: "auto" or a backend name
  // Which relaxation the endpoints are bounds of: "order d", or a mixed one with data-row blocks of a capped
  // localizing order ("tight" endpoints equal that relaxation's bound over every kept row).
  std::string relaxation;
  std::string executor;       // e.g. "fork (2 workers)"
  bool worker_rank = false;   // true on MPI worker ranks: they served jobs and hold no result
  std::vector<std::pair<double, double>> box;
  std::vector<std::string> parameter_names;
  // Contracted box of every orthant left at the end (index, box), and the cheap passes run in contracted boxes.
  std::vector<std::pair<int, std::vector<std::pair<double, double>>>> orthant_boxes;
  int contraction_passes_run = 0;
  // Endpoints solved again where a solve stopped short (BoundsOptions::stopped_short_refinements).
  int refine_jobs = 0, refine_tightened = 0;
  // Endpoints solved again in the box of the full pass's own bounds (BoundsOptions::endpoint_refinements).
  int endpoint_refine_jobs = 0, endpoint_refine_tightened = 0;
  // Exact row reduction per live orthant: {"orthant", "per_step": [{"step", "rows", "kept"}]}.
  std::vector<nlohmann::json> row_reduction;
  // Where the orthant bounds entering the endpoints came from (see dss/aggregate.hpp).
  std::map<std::string, int> bound_sources;
  // Certified points of D^ss(n) found by the edge-witness stage, the most extreme ones per parameter.
  std::vector<FeasiblePoint> feasible_points;
  bool clipped_to_box = false;
  // A run over a split box (dss/box_split.hpp): each piece's own summary as JSON, with its box.
  std::vector<nlohmann::json> pieces;
  // A run with automatic cuts (dss/box_split.hpp): {"rounds": each round's box, cut and intervals, the first
  // run first; "stopped": why no further round ran}. Null without automatic cuts.
  nlohmann::json auto_split;
  nlohmann::json to_json() const;
  bool all_guaranteed() const;
  // Every orthant proven empty (by verified certificates when verification is on): no parameter in the box
  // explains the data within the noise bound, so the model class or the noise bound is wrong.
  bool invalidated() const;
};

// Checks of a bounds run's settings, shared by ComputeBounds, the CLI and the Python module so that each bad
// value gets one message everywhere. Each returns false with the message in *error; the message names the
// setting as the Python keyword (the CLI adds its option's spelling in front).
// (The horizon's check, ValidHorizon, and MinimalOrder are in dss/hw_outer_set.hpp.)
constexpr int kMaxOrder = 20;
// Refinements of every open endpoint (BoundsOptions::endpoint_refinements): 0..kMaxEndpointRefinements.
constexpr int kMaxEndpointRefinements = 10;
// A relaxation order asked for at horizon n: MinimalOrder(n)..kMaxOrder.
bool ValidOrder(int order, int horizon, std::string* error);
// Parallel jobs: 0 (one per core) or more.
bool ValidThreads(int threads, std::string* error);
// Cheap passes in contracted boxes: 0 (no contraction)..10.
bool ValidContractionPasses(int passes, std::string* error);
// Re-solves of an endpoint resting on a solve that stopped short: 0 (never) or more.
bool ValidStoppedShortRefinements(int refinements, std::string* error);
// Re-solves of every open endpoint: 0 (never)..kMaxEndpointRefinements.
bool ValidEndpointRefinements(int refinements, std::string* error);
// The backend of a bounds run: "auto" or a name of sdp::AvailableSolvers().
bool ValidBoundsSolver(const std::string& name, std::string* error);
// The backend that solves the engine's relaxations of this order with data-row blocks capped at
// `block_order_cap` (-1: full order): `name` itself, or for "auto" the one measured best on them (docs/sdp.md):
// CSDP with hwbounds' Schur complement assembly (sdp/csdp_schur.cpp) at every order measured (order 2; order 3
// with 9 x 9 or full 45 x 45 data-row blocks, where it is 2 times faster than DSDP and its bound the tighter).
std::string SolverForOrder(const std::string& name, int order, int block_order_cap = -1);

BoundsSummary ComputeBounds(const BoundsOptions& options, const HwOuterSet& set,
                            const std::function<void(const BoundsProgress&)>& progress = {});

}  // namespace hw::dss
