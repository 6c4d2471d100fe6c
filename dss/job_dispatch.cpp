#include "dss/job_dispatch.hpp"

namespace hw::dss {

void DispatchJobs(EngineContext& ctx, const std::vector<std::pair<std::string, std::string>>& jobs,
                  const std::function<void(std::size_t, const nlohmann::json&, bool)>& on_done) {
  std::vector<std::string> specs;
  std::vector<std::size_t> spec_job;
  std::vector<std::pair<std::size_t, nlohmann::json>> cached;
  std::vector<std::string> keys;
  for (const auto& job : jobs) keys.push_back(job.second);
  ctx.cache.plan(keys);
  for (std::size_t i = 0; i < jobs.size(); ++i) {
    if (auto j = ctx.cache.load(jobs[i].second)) {
      cached.push_back({i, std::move(*j)});
      continue;
    }
    specs.push_back(jobs[i].first);
    spec_job.push_back(i);
  }
  ctx.counters.jobs_from_cache += static_cast<int>(cached.size());
  ctx.progress.FromCache(static_cast<int>(cached.size()));
  for (const auto& [i, j] : cached) on_done(i, j, true);
  ctx.executor.Map(specs, ctx.job, [&](std::size_t s, const sdp::JobResult& r) {
    const std::size_t i = spec_job[s];
    if (!r.ok) {  // a crashed or throwing job: reported by the caller, never dropped, not cached
      on_done(i, nlohmann::json{{"job_error", r.error}}, false);
      return;
    }
    auto j = nlohmann::json::parse(r.text);
    ctx.cache.store(jobs[i].second, j);
    on_done(i, j, false);
  });
}

}  // namespace hw::dss
