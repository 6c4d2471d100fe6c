#pragma once
// What a job's handler works with in the process that runs it, and the API every job kind implements (in the
// manner of SCS's linsys.h: each stage's file owns its kind and handler; dss/job_function.hpp registers them).
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "dss/engine_settings.hpp"
#include "dss/hw_outer_set.hpp"

namespace hw::dss {

// The run's settings, the prior outer set, and the outer set and each orthant's data rows in any box a job names,
// built on first use and kept (before a fork, workers inherit them).
class JobContext {
 public:
  JobContext(const EngineSettings& settings, const HwOuterSet& prior_set);
  const EngineSettings& settings() const { return settings_; }
  const HwOuterSet& prior_set() const { return prior_set_; }
  const HwOuterSet& set_in(const ParameterBox& box) const;
  const std::vector<DataConstraint>& rows_in(const ParameterBox& box, int l) const;

 private:
  const EngineSettings settings_;  // a copy: a job function may outlive the caller's settings
  const HwOuterSet& prior_set_;
  mutable std::mutex mutex_;
  mutable std::map<std::string, std::unique_ptr<HwOuterSet>> sets_;
  mutable std::map<std::pair<std::string, int>, std::vector<DataConstraint>> rows_;
};

// The answer (JSON) to one spec of a job kind.
using JobHandler = nlohmann::json (*)(const JobContext& job, const nlohmann::json& spec);

}  // namespace hw::dss
