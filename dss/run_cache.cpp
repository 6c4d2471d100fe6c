#include "dss/run_cache.hpp"

#include <cstdint>
#include <filesystem>

#include <fmt/format.h>

#include "core/atomic_write.hpp"
#include "core/json_input.hpp"

namespace hw::dss {
namespace fs = std::filesystem;
namespace {

uint64_t fnv(uint64_t h, const std::string& s) {
  for (unsigned char c : s) h = (h ^ c) * 1099511628211ull;
  return h;
}

// The run directory's record of the jobs dispatched so far (RunCache::plan).
constexpr const char* kPlanFile = "planned.json";

// The job keys in a plan file, or nothing when it is missing or damaged (then its count is not trusted).
std::optional<std::set<std::string>> ReadPlannedJobs(const fs::path& file) {
  const auto j = ReadStoredJson(file.string());
  if (!j) return std::nullopt;
  try {
    return j->at("planned_jobs").get<std::set<std::string>>();
  } catch (...) {
    return std::nullopt;
  }
}

}  // namespace

RunCache::RunCache(const std::string& root, const std::string& key, const nlohmann::json& meta) {
  if (root.empty()) return;
  const fs::path dir = fs::path(root) / key;
  fs::create_directories(dir / "jobs");
  if (!fs::exists(dir / "problem.json")) write_text_atomic((dir / "problem.json").string(), meta.dump(2));
  dir_ = dir.string();
  if (auto keys = ReadPlannedJobs(dir / kPlanFile)) {
    planned_ = std::move(*keys);
    planned_by_earlier_runs_ = planned_.size();
    earlier_plan_known_ = true;
  }
}

std::optional<nlohmann::json> RunCache::load(const std::string& name) const {
  if (!enabled()) return std::nullopt;
  return ReadStoredJson((fs::path(dir_) / "jobs" / (name + ".json")).string());
}

void RunCache::store(const std::string& name, const nlohmann::json& j) const {
  if (enabled()) write_text_atomic((fs::path(dir_) / "jobs" / (name + ".json")).string(), j.dump());
}

int RunCache::stored_jobs() const {
  if (!enabled()) return 0;
  int n = 0;
  for (const auto& e : fs::directory_iterator(fs::path(dir_) / "jobs"))
    if (e.path().extension() == ".json") ++n;
  return n;
}

void RunCache::plan(const std::vector<std::string>& names) const {
  if (!enabled()) return;
  const std::size_t before = planned_.size();
  planned_.insert(names.begin(), names.end());
  if (planned_.size() != before || !fs::exists(fs::path(dir_) / kPlanFile))
    write_text_atomic((fs::path(dir_) / kPlanFile).string(), nlohmann::json{{"planned_jobs", planned_}}.dump());
}

std::optional<std::string> RunCache::resume_line() const {
  const int stored = stored_jobs();
  if (stored == 0) return std::nullopt;
  constexpr const char* kRest = "each phase counts only the jobs still to run";
  if (!earlier_plan_known_)  // a directory written before planned.json existed, or a damaged plan
    return fmt::format("resuming: {} finished jobs from {} (the earlier run's plan is not recorded); {}", stored,
                       dir_, kRest);
  std::size_t finished = 0;
  for (const auto& name : planned_) finished += load(name).has_value() ? 1 : 0;
  return fmt::format("resuming: {} of {} jobs planned so far are finished, from {}; later phases may plan more, and {}",
                     finished, planned_by_earlier_runs_, dir_, kRest);
}

std::string BoxHash(const ParameterBox& box) { return TextHash(nlohmann::json(box).dump()); }

std::string TextHash(const std::string& text) { return fmt::format("{:016x}", fnv(1469598103934665603ull, text)); }

}  // namespace hw::dss
