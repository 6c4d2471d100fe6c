#pragma once
// The engine's one way to run jobs: the run cache answers what it holds, the executor the rest.
#include <cstddef>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "dss/engine_context.hpp"

namespace hw::dss {

// Runs jobs (spec, cache key) through the cache and the executor; `on_done(i, answer, cached)` sees every
// answer (cached ones first). A failed job (crash, exception) answers {"job_error": why} and is not cached.
void DispatchJobs(EngineContext& ctx, const std::vector<std::pair<std::string, std::string>>& jobs,
                  const std::function<void(std::size_t, const nlohmann::json& answer, bool cached)>& on_done);

}  // namespace hw::dss
