#pragma once
// Guaranteed parameter intervals of a Hammerstein–Wiener model over D^ss(n) (paper 001, eqs. 22-33).
//
// Pipeline, per run:
//  1. LP screen of every sign orthant (ScreenWithLinearProgram): an infeasible LP proves the orthant empty.
//  2. Cheap pass at the minimal order delta0 = ceil((n+1)/2) for every objective (min/max of every
//     parameter) of every surviving orthant, by constraint generation. An infeasible relaxation proves
//     the orthant empty.
//  3. Full pass at order delta: for each objective, orthants are solved in order of their cheap bound,
//     most extreme first, and an orthant is skipped when its cheap bound cannot move the aggregated
//     interval (its order-delta bound is at least as tight as its order-delta0 bound: Property 3).
//     The result equals solving every orthant at order delta.
// Guarantees: every reported endpoint is a valid bound (dual side of the SDP) of a relaxation of
// D^ss(n) intersected with the prior box. A failed solve never disappears: the endpoint falls back to
// the same orthant's cheap-order bound, or to the box edge, and is marked "conservative".
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "relax/constraint_generation.hpp"
#include "relax/hw_outer_set.hpp"
#include "sdp/job_executor.hpp"

namespace hw::relax {

struct BoundsOptions {
  int order = 3;                 // delta of the reported intervals
  bool cheap_pass = true;        // solve the minimal order first to skip objectives (recommended)
  bool lp_screen = true;
  std::string solver = "sdpa";
  bool retry_with_other_solver = true;  // a failed solve is repeated with the other backend before falling back
  // Local parallel jobs. CSDP and SDPA are not thread-safe, so jobs run in forked worker processes
  // (sdp::ForkExecutor); 0 = one per core. Ignored when `executor` is set.
  int threads = 0;
  // Where jobs run (sdp/job_executor.hpp): null = ForkExecutor(threads); sdp::MpiExecutor for MPI runs.
  std::shared_ptr<sdp::JobExecutor> executor;
  std::string run_dir;           // resumable cache; empty = none
  std::vector<std::string> parameters;  // intervals to compute (names); empty = every parameter
  ConstraintGenerationOptions generation;  // its order is set per pass
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
  double half_width() const { return 0.5 * (upper.value - lower.value); }
};

struct OrthantReport {
  int index = 0;
  std::string signs;    // e.g. "alpha2+ alpha3+ Q1_1+ ..."
  std::string status;   // "empty (LP)", "empty (order k)", "solved", "failed (conservative)"
};

struct BoundsProgress {
  std::string phase;
  int done = 0, total = 0;
  double elapsed_seconds = 0.0, eta_seconds = 0.0;
};

struct BoundsSummary {
  std::vector<ParameterInterval> intervals;
  std::vector<OrthantReport> orthants;
  int orthants_total = 0, orthants_empty = 0, orthants_solved = 0, orthants_failed = 0;
  int sdp_jobs = 0;           // relaxation jobs run (cached ones excluded)
  int sdp_solves = 0;         // SDP solves including constraint-generation rounds
  int jobs_from_cache = 0;
  double median_solve_seconds = 0.0;
  double solve_seconds = 0.0, verify_seconds = 0.0;  // totals over the jobs run (cache excluded); verify incl. re-solves
  std::size_t largest_moments = 0, largest_blocks = 0;
  double wall_seconds = 0.0;
  int order = 0, horizon = 0;
  std::string solver;
  std::string executor;       // e.g. "fork (2 workers)"
  bool worker_rank = false;   // true on MPI worker ranks: they served jobs and hold no result
  std::vector<std::pair<double, double>> box;
  std::vector<std::string> parameter_names;
  nlohmann::json to_json() const;
  bool all_guaranteed() const;
};

BoundsSummary ComputeBounds(const BoundsOptions& options, const HwOuterSet& set,
                            const std::function<void(const BoundsProgress&)>& progress = {});

}  // namespace hw::relax
