#pragma once
// Stage 3 of the bound engine (before any SDP): endpoints that a feasible point settles.
//
// When D^ss(n) reaches the prior box's edge in a parameter (a thin set in a wide box does, e.g. the scaling ray
// of paper 001's example at 31 dB), the relaxation's bound of that objective is the box edge too: the box
// constraints hold in the relaxation, and a feasible point p of orthant l with p_k at the edge is a feasible
// point of every relaxation of orthant l. Such a point, found by local optimisation (dss/inner_points.hpp)
// and checked by evaluating every inequality of the orthant with a rounding-error allowance, settles the
// objective in that orthant exactly, and the interval's endpoint in every orthant (no orthant can go beyond the
// box), without an SDP. The settled endpoint is the one the full relaxation would give: nothing is loosened.
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "dss/job_context.hpp"
#include "dss/job_dispatch.hpp"
#include "dss/pipeline_state.hpp"
#include "dss/edge_witness_options.hpp"

namespace hw::dss {

// What the stage found besides what it hands on in the pipeline state (SettleEdgesByWitnesses).
struct EdgeWitnessResult {
  std::map<ObjectiveKey, std::vector<double>> points;  // the witness of each settling orthant (original units)
  // The certified feasible points most extreme in some objective's parameter (one per point, in objective
  // order): inner witnesses a user can check, and the inner side of each interval.
  std::vector<FeasiblePoint> feasible_points;
  int local_solves = 0;
  double seconds = 0.0;
};

// The smallest slack of the inequalities of orthant l (sign and data rows, unscaled) at p, each lowered by a
// bound on its floating-point evaluation error; >= 0 means p lies in D^ss(n) of orthant l despite rounding.
double CertifiedMinSlack(const HwOuterSet& set, int l, const std::vector<double>& p);

// The points that are certified feasible points of their orthant (a live orthant, inside its box,
// CertifiedMinSlack >= 0), in key order.
std::vector<FeasiblePoint> CertifiedFeasiblePoints(const HwOuterSet& set, const std::vector<OrthantWork>& orthants,
                                                   const std::map<ObjectiveKey, std::vector<double>>& points);

// Per objective, the most extreme value of its parameter over `points`; objectives without one are absent.
std::map<int, double> WitnessedExtremes(const std::vector<Objective>& objectives,
                                        const std::vector<FeasiblePoint>& points);

// The first point most extreme in each objective's parameter, without repeats, in objective order.
std::vector<FeasiblePoint> ExtremeFeasiblePoints(const std::vector<Objective>& objectives,
                                                 const std::vector<FeasiblePoint>& points);

// Objective `o` in orthant w settled without an SDP when w's box and sign constraints alone bound it at or
// beyond `witnessed` (a certified feasible value of another part): a sign polynomial c * x_k fixes x_k's sign in
// the orthant (min x_k >= 0 or max x_k <= 0 there). The relaxation's bound lies beyond that sign bound, the
// endpoint at or before the value, so the orthant cannot move the endpoint. Empty when it does not apply.
std::optional<JobOutcome> SettleBySignBeyondWitness(const HwOuterSet& set, const OrthantWork& w, const Objective& o,
                                                    double witnessed);

// The spec of a witness job: a local extreme of objective `o` over orthant w's rows (the kept ones), from
// `starts` in turn until one gives a feasible point (AnswerWitnessJob answers {"found", "point", "solves"}).
std::string WitnessSpec(const OrthantWork& w, const Objective& o, const std::vector<std::vector<double>>& starts);

// Runs witness jobs (spec, cache key) through the cache and the executor; answers in job order (an empty object
// for a job that failed); adds their local solves to *solves; one progress step per job.
std::vector<nlohmann::json> RunWitnessJobs(EngineContext& ctx, const std::vector<std::pair<std::string, std::string>>& jobs,
                                           int* solves);

// The witness job kind: {"kind": "witness", "l", "param", "dir", "starts", "rows"} -> {"found", "point", "solves"}.
inline constexpr char kWitnessJob[] = "witness";
nlohmann::json AnswerWitnessJob(const JobContext& job, const nlohmann::json& spec);

// The stage: fills state.settled with the objectives settled here, in the orthant whose point attains the edge
// (solved, tight, origin kFeasiblePointAtEdge) and in the other live orthants (skipped: the interval already
// reaches the box edge); and, with stop_beyond_witnesses, state.witnessed: per objective index the most extreme
// value of its parameter over every certified feasible point found (in any live orthant, inside its box). The
// endpoint is at least that extreme, so an orthant whose valid bound is already beyond it cannot move the
// endpoint (pop/constraint_generation.hpp, stop_beyond).
EdgeWitnessResult SettleEdgesByWitnesses(const EdgeWitnessOptions& options, EngineContext& ctx, PipelineState& state);

}  // namespace hw::dss
