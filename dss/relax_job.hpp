#pragma once
// The relaxation job kind, which every pass runs: a bound of one objective over one orthant at one order, by
// constraint generation over the orthant's kept data rows (pop/constraint_generation.hpp).
#include <cmath>
#include <vector>

#include <nlohmann/json.hpp>

#include "dss/job_context.hpp"
#include "dss/job_dispatch.hpp"
#include "dss/job_outcome.hpp"
#include "pop/moment_relaxation.hpp"

namespace hw::dss {

// {"kind": "relax", "l", "param", "dir", "d", "box", "rows", "initial", ["max_rounds"], ["stop_beyond"]} -> JobOutcome.
inline constexpr char kRelaxJob[] = "relax";
nlohmann::json AnswerRelaxJob(const JobContext& job, const nlohmann::json& spec);

// The part of a relaxation job that every round keeps: min (dir -1) / max (+1) of parameter `param` over the box
// and the sign constraints of orthant l (the data rows are the candidates of constraint generation).
pop::PolyProblem OrthantObjectiveCore(const HwOuterSet& set, int l, const Objective& objective);

// One relaxation job: objective over an orthant at an order, with blocks for `initial` (indices into rows).
struct RelaxJob {
  const OrthantWork* orthant = nullptr;
  Objective objective;
  int order = 0;
  std::vector<int> initial;
  int max_rounds = 0;  // 0 = the generation options' limit
  // A value of the objective's parameter attained by a certified feasible point (dss/edge_witness.hpp): the job
  // may end once its bound is beyond it (ConstraintGenerationOptions::stop_beyond). NaN: none.
  double stop_beyond = NAN;
};

// Runs relaxation jobs (cached ones are read), adds to the counters, reports progress (one step per job), and
// marks orthants that a job proved empty. Failed jobs come back with status kFailed and the reason.
std::vector<JobOutcome> RunRelaxationJobs(EngineContext& ctx, const std::vector<RelaxJob>& jobs,
                                          std::vector<OrthantWork>& orthants);

}  // namespace hw::dss
