#pragma once
// The run cache of a bounds run: every finished job on disk under its key, so that a run that stops resumes where
// it was, and the hashes that name jobs by their inputs.
#include <cstddef>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "dss/hw_outer_set.hpp"

namespace hw::dss {

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

// A short hash of a box (cache keys of jobs in contracted boxes).
std::string BoxHash(const ParameterBox& box);
// A short hash of a text (cache keys of jobs named by their inputs).
std::string TextHash(const std::string& text);

}  // namespace hw::dss
