#include "dss/moment_witness.hpp"

#include <algorithm>
#include <chrono>
#include <map>

#include <fmt/format.h>

#include "dss/edge_witness.hpp"

namespace hw::dss {

namespace {

std::vector<double> ClippedToBox(std::vector<double> p, const ParameterBox& box) {
  for (std::size_t i = 0; i < p.size(); ++i) p[i] = std::clamp(p[i], box[i].first, box[i].second);
  return p;
}

}  // namespace

MomentWitnessResult FeasiblePointsFromMoments(const MomentWitnessOptions& options, EngineContext& ctx,
                                              const PipelineState& state) {
  MomentWitnessResult result;
  const std::vector<Objective>& objectives = state.objectives;
  const std::vector<int>& wanted = state.wanted_objectives;
  const PassOutcomes& outcomes = state.full;
  const std::vector<OrthantWork>& orthants = state.orthants;
  if (!options.enabled) return result;
  const auto t0 = std::chrono::steady_clock::now();
  std::vector<std::pair<std::string, std::string>> jobs;
  std::vector<ObjectiveKey> keys;
  for (const auto& w : orthants) {
    if (w.empty()) continue;
    for (int j : wanted) {
      const auto it = outcomes.find({w.index, j});
      if (it == outcomes.end() || it->second.status != JobStatus::kSolved) continue;
      const auto& moments = it->second.first_moments;
      if (moments.size() != w.box.size()) continue;  // no solved round (or read from an older cache)
      const std::string spec = WitnessSpec(w, objectives[j], {ClippedToBox(moments, w.box)});
      jobs.push_back({spec, fmt::format("moment_witness_l{}_o{}_d{}_{}", w.index, j, options.order, TextHash(spec))});
      keys.push_back({w.index, j});
    }
  }
  result.jobs = static_cast<int>(jobs.size());
  if (!jobs.empty()) ctx.progress.Phase("feasible points from the relaxations' moments", result.jobs);
  const auto answers = RunWitnessJobs(ctx, jobs, &result.local_solves);
  std::map<ObjectiveKey, std::vector<double>> found;
  for (std::size_t i = 0; i < answers.size(); ++i)
    if (answers[i].value("found", false)) found[keys[i]] = answers[i].at("point").get<std::vector<double>>();
  result.feasible_points = CertifiedFeasiblePoints(ctx.set, orthants, found);
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return result;
}

}  // namespace hw::dss
