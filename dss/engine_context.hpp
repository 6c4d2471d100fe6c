#pragma once
// What every stage of the engine shares: its settings, the outer set, where jobs run, the run cache, the
// counters and the progress, and the orthants still alive.
#include <optional>
#include <vector>

#include <nlohmann/json.hpp>

#include "dss/bounds_summary.hpp"
#include "dss/engine_settings.hpp"
#include "dss/hw_outer_set.hpp"
#include "dss/progress_reporter.hpp"
#include "dss/run_cache.hpp"
#include "sdp/job_executor.hpp"

namespace hw::dss {

// Counters every stage adds to (they end up in BoundsSummary).
struct EngineCounters {
  int sdp_jobs = 0, sdp_solves = 0, jobs_from_cache = 0;
  int jobs_stopped_beyond_witness = 0;  // jobs that ended once their bound passed a certified feasible point's
  int jobs_settled_by_sign = 0;  // jobs not run: the orthant's sign constraints already bound them beyond such a value
  double solve_seconds = 0.0, verify_seconds = 0.0;
  std::vector<double> solve_times;  // per SDP solve (job time / rounds)
  std::size_t largest_moments = 0, largest_blocks = 0;
};

struct EngineContext {
  const EngineSettings& settings;
  const HwOuterSet& set;
  sdp::JobExecutor& executor;
  const sdp::JobFunction& job;
  const RunCache& cache;
  EngineCounters& counters;
  ProgressReporter& progress;
};

// An orthant that is still alive, with its box and its kept data rows (indices into data_constraints(l)).
struct OrthantWork {
  int index = 0;
  ParameterBox box;
  std::vector<int> rows;
  std::vector<nlohmann::json> reduction;  // per step: {"step", "rows", "kept"} (JSON of RowGroupCount)
  std::optional<EmptinessCertificate> certificate;  // the certificate that proved it empty (ProveEmpty)
  bool empty() const { return certificate.has_value(); }
  void ProveEmpty(const EmptinessCertificate& c) { certificate = c; }
};

// Maps a working set (indices into a job's rows) back to data-row indices of the orthant.
inline std::vector<int> RowsOfWorkingSet(const OrthantWork& orthant, const std::vector<int>& working_set) {
  std::vector<int> rows;
  for (int i : working_set) rows.push_back(orthant.rows.at(i));
  return rows;
}

}  // namespace hw::dss
