#pragma once
// A comparison study: R seeded Monte Carlo runs of every selected method on one scenario.
//
// Parallelism is process-level: CSDP and SDPA keep process-wide state, so `jobs` forked worker processes
// each run whole runs (all methods of a run, set-membership SDPs solved in-process) on the shared executor
// (sdp::ForkExecutor); the parent stores each run's JSON in the shared run cache (dss::RunCache, written
// atomically) as DIR/runs/<study key>/jobs/run_NNNN.json, the key being the hash of the study's inputs (scenario +
// methods + seed, DIR/runs/<study key>/problem.json). A run whose file is there is not recomputed, so an
// interrupted study resumes; a damaged file is recomputed.
// The summary is computed from the per-run files alone (never from in-memory results), so the tables
// always agree with the files they summarise.
#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "compare/scenario.hpp"

namespace hw::compare {

struct StudyOptions {
  std::vector<std::string> methods = {"setmembership", "brouri", "esmaeilani"};
  int runs = 20;
  std::uint64_t seed = 1;
  std::string out_dir;
  int jobs = 2;       // worker processes; 0 = one per core
  bool plots = true;  // gnuplot PNGs (skipped, with a note, when gnuplot is missing)
  bool quiet = false;
  bool IsValid(std::string* error) const;
};

struct StudySummary {
  nlohmann::json summary;  // what DIR/summary.json holds
  bool coverage_ok = true;  // every guaranteed interval of every run contains the truth
  bool all_ok = true;       // no applicable method failed in any run
  int runs_computed = 0, runs_resumed = 0;
  double wall_seconds = 0.0;
  std::string message;
};

StudySummary RunStudy(const StudyOptions& options, const Scenario& scenario);

// Aggregation of existing per-run files (used by RunStudy; public for tests and re-reporting).
nlohmann::json Aggregate(const Scenario& scenario, const std::vector<nlohmann::json>& runs);
// summary.md text and the gnuplot plots (report.cpp).
std::string SummaryMarkdown(const nlohmann::json& summary);
std::string WritePlots(const std::string& out_dir, const Scenario& scenario, const std::vector<nlohmann::json>& runs,
                       const nlohmann::json& summary);  // returns a note (empty = all written)

}  // namespace hw::compare
