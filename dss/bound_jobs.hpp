#pragma once
// The jobs of the bound engine, as text, so that one job function answers them in this process, in forked
// workers or on other MPI ranks (sdp/job_executor.hpp). A job depends only on (options, set) and its spec, never
// on which worker runs it or when, so results do not depend on timing:
//   {"kind": "lp", "l"}                          LP screen of orthant l (emptiness, verified);
//   {"kind": "reduce", "l", "box", ["step"]}     exact row reduction of orthant l's data rows of horizon step
//                                                `step` (all steps without it; dss/row_reduction.hpp);
//   {"kind": "witness", "l", "param", "dir", "starts", "rows"}
//                                                a feasible local extreme of a parameter over orthant l, from the
//                                                starts in turn, over the data rows `rows` (dss/edge_witness.hpp);
//   {"kind": "relax", "l", "param", "dir", "d", "box", "rows", "initial", ["max_rounds"], ["stop_beyond"]}
//                                                bound min (dir -1) / max (+1) of a parameter over orthant l at
//                                                order d in `box`, over the data rows `rows`, starting with blocks
//                                                for `initial` (indices into rows); it may end once its bound
//                                                is beyond stop_beyond (a value attained elsewhere).
// Also here: the engine's context shared by its stages, the run cache, and the dispatcher that reads cached
// jobs and runs the rest on the executor.
#include <cmath>
#include <functional>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "dss/hw_outer_set.hpp"
#include "dss/set_membership.hpp"
#include "pop/moment_relaxation.hpp"
#include "sdp/job_executor.hpp"

namespace hw::dss {

using Box = std::vector<std::pair<double, double>>;

// One objective: min (dir = -1) or max (dir = +1) of parameter `param`.
struct Objective {
  int param = 0;
  int dir = -1;
};

// A relaxation job's answer (bounds in original units).
struct JobOutcome {
  std::string status;  // "solved", "infeasible", "failed"
  double bound = 0.0;
  bool tight = false;
  std::string message;
  int rounds = 0;
  int sdp_iterations = 0;
  double seconds = 0.0;
  std::size_t moments = 0, blocks = 0;
  std::vector<int> working_set;  // indices into the job's rows that had blocks in the last LMI
  std::vector<int> active_set;   // the part of it with non-negligible multipliers (warm start of other jobs)
  // "off", "verified", "unverified"; bound is the verified value when verified, float_bound the solver's.
  std::string verification = "off";
  double float_bound = 0.0, correction = 0.0, verify_seconds = 0.0;
  std::string origin = "none";     // BoundOrigin: "final round" or "earlier round"
  int bound_round = 0;
  bool unfinished = false;         // the bound is the verified last iterate of a solve that stopped short
  bool beyond_known_value = false; // ended once its bound passed stop_beyond: valid, cannot move the endpoint
  // The last solved round's first-order moments, original units (empty when no round solved): the relaxation's
  // guess of the extreme point, a start for a local search of a feasible point there (dss/moment_witness.hpp).
  std::vector<double> first_moments;
  nlohmann::json to_json() const;
  static JobOutcome from_json(const nlohmann::json& j);
};

// Cache of finished jobs in run_dir/<problem hash>/jobs/; a damaged file is recomputed, never trusted.
// Next to jobs/, planned.json lists the key of every job dispatched so far (by this run and the runs before it):
// jobs are planned phase by phase, so the whole run's count is not known in advance, but the jobs the earlier
// runs planned are, and a resumed run reports how many of those are finished.
class RunCache {
 public:
  RunCache() = default;
  RunCache(const std::string& root, const std::string& key, const nlohmann::json& meta);
  bool enabled() const { return !dir_.empty(); }
  std::string path() const { return dir_; }
  std::optional<nlohmann::json> load(const std::string& name) const;
  void store(const std::string& name, const nlohmann::json& j) const;
  int stored_jobs() const;  // finished jobs on disk
  // Adds the keys of jobs about to be dispatched to planned.json (written atomically).
  void plan(const std::vector<std::string>& names) const;
  // The line a resumed run starts with ("resuming: K of M jobs planned so far are finished, in DIR; ..."), or
  // nothing when the directory holds no finished job. Counts what the earlier runs left, before this run plans.
  std::optional<std::string> resume_line() const;

 private:
  std::string dir_;
  // Keys in planned.json: read when the cache opens (the earlier runs' plan), then grown by plan().
  mutable std::set<std::string> planned_;
  std::size_t planned_by_earlier_runs_ = 0;
  bool earlier_plan_known_ = false;  // planned.json was there and readable
};

// Counters every stage adds to (they end up in BoundsSummary).
struct EngineCounters {
  int sdp_jobs = 0, sdp_solves = 0, jobs_from_cache = 0;
  int jobs_stopped_beyond_witness = 0;  // jobs that ended once their bound passed a certified feasible point's
  int jobs_settled_by_sign = 0;  // jobs not run: the orthant's sign constraints already bound them beyond such a value
  double solve_seconds = 0.0, verify_seconds = 0.0;
  std::vector<double> solve_times;  // per SDP solve (job time / rounds)
  std::size_t largest_moments = 0, largest_blocks = 0;
};

// Progress of the whole run: phases with jobs done / total, ETA from the jobs done in the phase.
class ProgressReporter {
 public:
  ProgressReporter(std::function<void(const BoundsProgress&)> sink);
  void Phase(const std::string& name, int total);  // starts a phase
  void Done(int jobs = 1);
  // `jobs` of the phase come from the run cache: they leave the total, and their next Done() calls are not
  // counted, so done/total and the ETA measure the work still to run.
  void FromCache(int jobs);
  void Message(const std::string& text);            // a one-off line (e.g. resuming)

 private:
  std::function<void(const BoundsProgress&)> sink_;
  std::string phase_;
  int done_ = 0, total_ = 0, from_cache_ = 0, uncounted_ = 0;
  double phase_start_ = 0.0;
};

// What every stage shares.
struct EngineContext {
  const BoundsOptions& options;  // validated, engine-wide SDP settings applied
  const HwOuterSet& set;
  sdp::JobExecutor& executor;
  const sdp::JobFunction& job;
  const RunCache& cache;
  EngineCounters& counters;
  ProgressReporter& progress;
};

// The part of a relaxation job that every round keeps: min (dir -1) / max (+1) of parameter `param` over the box
// and the sign constraints of orthant l (the data rows are the candidates of constraint generation).
pop::PolyProblem OrthantObjectiveCore(const HwOuterSet& set, int l, const Objective& objective);

// Builds the job function for (options, set): the outer set in every box a job names and each orthant's data
// rows are built on first use and kept (before a fork, workers inherit them).
sdp::JobFunction MakeJobFunction(const BoundsOptions& options, const HwOuterSet& set);

// Runs jobs (spec, cache key) through the cache and the executor; `on_done(i, answer, cached)` sees every
// answer (cached ones first). A failed job (crash, exception) answers {"job_error": why} and is not cached.
void DispatchJobs(EngineContext& ctx, const std::vector<std::pair<std::string, std::string>>& jobs,
                  const std::function<void(std::size_t, const nlohmann::json& answer, bool cached)>& on_done);

// An orthant that is still alive, with its box and its kept data rows (indices into data_constraints(l)).
struct OrthantWork {
  int index = 0;
  Box box;
  std::vector<int> rows;
  std::vector<nlohmann::json> reduction;  // per step: {"step", "rows", "kept"} (JSON of RowGroupCount)
  std::string status = "undecided";       // or "empty (...)": the certificate that proved it empty
  std::optional<EmptinessCertificate> certificate;  // set with the status by ProveEmpty
  bool empty() const { return status.rfind("empty", 0) == 0; }
  void ProveEmpty(const EmptinessCertificate& c) {
    certificate = c;
    status = c.status();
  }
};

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
// marks orthants that a job proved empty. Failed jobs come back with status "failed" and the reason.
std::vector<JobOutcome> RunRelaxationJobs(EngineContext& ctx, const std::vector<RelaxJob>& jobs,
                                          std::vector<OrthantWork>& orthants);

// Maps a working set (indices into a job's rows) back to data-row indices of the orthant.
std::vector<int> RowsOfWorkingSet(const OrthantWork& orthant, const std::vector<int>& working_set);

// A short hash of a box (cache keys of jobs in contracted boxes).
std::string BoxHash(const Box& box);
// A short hash of a text (cache keys of jobs named by their inputs).
std::string TextHash(const std::string& text);

}  // namespace hw::dss
