#pragma once
// What a bounds run reports (dss/set_membership.hpp): the intervals with their endpoints' statuses, each sign
// orthant's status and certificate, counts, times, and the JSON of it all.
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "dss/inner_points.hpp"
#include "dss/statuses.hpp"

namespace hw::dss {

struct Endpoint {
  double value = 0.0;
  EndpointStatus status = EndpointStatus::kUnknown;
  std::string note;
  int orthant = -1;                // orthant attaining the endpoint
  bool tight = false;              // equals the full relaxation's bound (constraint generation converged)
  // kVerified: every orthant bound entering the value was verified rigorously (sdp/verified_bound.hpp);
  // kUnverified: at least one is the solver's floating-point bound; kNotRun ("off"): verification disabled.
  sdp::VerifyStatus verification = sdp::VerifyStatus::kNotRun;
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
  // kLinearProgram: the LP screen is infeasible; kRelaxation: the relaxation of order `order` is infeasible;
  // kCrossedBounds: the rigorous lower and upper bounds of a parameter at order `order` cross;
  // kPieces: empty in every piece of a split box (dss/box_split.hpp), `order` the highest order used there.
  CertificateKind kind = CertificateKind::kLinearProgram;
  int order = 0;                // relaxation order (0 for the LP screen)
  bool contracted_box = false;  // proven in the orthant's contracted box, which holds all its points of the prior box
  bool verified = false;        // checked in interval arithmetic; false: the solver's floating-point certificate
  std::string status() const;   // the orthant's status: "empty (LP)", "empty (order 2, contracted box)", ...
  nlohmann::json to_json() const;
};

struct OrthantReport {
  int index = 0;
  std::string signs;    // e.g. "alpha2+ alpha3+ Q1_1+ ..."
  OrthantStatus status = OrthantStatus::kUndecided;
  std::optional<EmptinessCertificate> certificate;  // of an empty orthant
  // "empty (LP)", "empty (order k)", ... (the certificate's status), "solved", "failed (conservative fallback)".
  std::string status_text() const;
  bool empty() const { return status == OrthantStatus::kEmpty; }
};

struct BoundsProgress {
  std::string phase;   // with done = total = -1: a one-off message (e.g. "resuming: ...")
  int done = 0, total = 0;  // of the jobs still to run in this phase (jobs read from the run cache excluded)
  int from_cache = 0;       // jobs of this phase read from the run cache so far
  double elapsed_seconds = 0.0, eta_seconds = 0.0;
  // The parameter whose relaxation job finished last in this phase, with its interval over the phase's finished
  // jobs so far: each side the most extreme bound they gave (the finished interval is at least as wide; a side no
  // job has bounded yet is absent). Empty name: no bound yet in this phase.
  std::string so_far_parameter;
  std::optional<double> so_far_lower, so_far_upper;
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
  ParameterBox box;
  std::vector<std::string> parameter_names;
  // Contracted box of every orthant left at the end (index, box), and the cheap passes run in contracted boxes.
  std::vector<std::pair<int, ParameterBox>> orthant_boxes;
  int contraction_passes_run = 0;
  // Endpoints solved again where a solve stopped short (BoundsOptions::stopped_short_refinements).
  int refine_jobs = 0, refine_tightened = 0;
  // Endpoints solved again in the box of the full pass's own bounds (BoundsOptions::endpoint_refinements).
  int endpoint_refine_jobs = 0, endpoint_refine_tightened = 0;
  // Exact row reduction per live orthant: {"orthant", "per_step": [{"step", "rows", "kept"}]}.
  std::vector<nlohmann::json> row_reduction;
  // Where the orthant bounds entering the endpoints came from (see dss/aggregate.hpp).
  std::map<BoundSource, int> bound_sources;
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

}  // namespace hw::dss
