#include "dss/refine_pass.hpp"

#include <algorithm>
#include <cmath>
#include <set>
#include <string>

#include "dss/box_contraction.hpp"
#include "dss/row_reduction.hpp"

namespace hw::dss {
namespace {

bool Beyond(int dir, double a, double b) { return dir < 0 ? a < b : a > b; }

bool Usable(const JobOutcome& r) { return r.status == JobStatus::kSolved || r.status == JobStatus::kSkipped; }

// Solved outcomes of live orthants among `wanted` that are their objective's endpoint (no other live orthant's
// solved or skipped bound lies beyond) and that `qualifies` accepts. Ascending order.
template <typename Qualifies>
std::vector<std::pair<int, int>> EndpointsWhere(const std::vector<Objective>& objectives,
                                                const std::vector<int>& wanted, const PassOutcomes& full,
                                                const std::vector<OrthantWork>& orthants, Qualifies qualifies) {
  std::vector<std::pair<int, int>> out;
  const std::set<int> wanted_set(wanted.begin(), wanted.end());
  std::set<int> alive;
  for (const auto& w : orthants)
    if (!w.empty()) alive.insert(w.index);
  for (const auto& [key, r] : full) {
    const auto [l, o] = key;
    if (!alive.count(l) || !wanted_set.count(o) || r.status != JobStatus::kSolved || !qualifies(o, r)) continue;
    const int dir = objectives[o].dir;
    bool endpoint = true;
    for (const auto& [other_key, other] : full)
      if (other_key.second == o && other_key.first != l && alive.count(other_key.first) && Usable(other) &&
          Beyond(dir, other.bound, r.bound))
        endpoint = false;
    if (endpoint) out.push_back(key);
  }
  return out;
}

}  // namespace

std::vector<std::pair<int, int>> StoppedShortEndpoints(const std::vector<Objective>& objectives,
                                                       const std::vector<int>& wanted, const PassOutcomes& full,
                                                       const std::vector<OrthantWork>& orthants) {
  return EndpointsWhere(objectives, wanted, full, orthants, [](int, const JobOutcome& r) { return r.unfinished; });
}

std::vector<std::pair<int, int>> OpenEndpoints(const std::vector<Objective>& objectives, const std::vector<int>& wanted,
                                               const PassOutcomes& full, const std::vector<OrthantWork>& orthants,
                                               const std::map<int, double>& witnessed) {
  return EndpointsWhere(objectives, wanted, full, orthants, [&](int o, const JobOutcome& r) {
    const auto it = witnessed.find(o);
    if (it == witnessed.end()) return true;
    const double allowance = 1e-6 * std::max(1.0, std::abs(it->second));
    return Beyond(objectives[o].dir, r.bound, it->second + objectives[o].dir * allowance);
  });
}

RefinePassResult RefineEndpoints(const RefinePassOptions& options, EngineContext& ctx, PipelineState& state) {
  RefinePassResult result;
  const std::vector<Objective>& objectives = state.objectives;
  const std::vector<int>& wanted = state.wanted_objectives;
  const std::map<int, double>& witnessed = state.witnessed;
  std::vector<OrthantWork>& orthants = state.orthants;
  PassOutcomes& outcomes = state.full;
  std::map<int, std::size_t> position;  // orthant index -> position in `orthants`
  for (std::size_t i = 0; i < orthants.size(); ++i) position[orthants[i].index] = i;
  const bool verify_on = ctx.settings.verify();
  for (int pass = 0; pass < options.passes; ++pass) {
    const auto targets = options.every_endpoint
                             ? OpenEndpoints(objectives, wanted, outcomes, orthants, witnessed)
                             : StoppedShortEndpoints(objectives, wanted, outcomes, orthants);
    if (targets.empty()) break;
    ++result.passes_run;
    // The targets' orthants, contracted to this pass's verified bounds, with their rows reduced again; an
    // orthant whose box did not move would repeat the same solves.
    std::set<int> target_orthants;
    for (const auto& [l, o] : targets) target_orthants.insert(l);
    const std::set<int> moved_index =
        ContractAndReduceRows(ctx, objectives, outcomes, target_orthants, orthants, options.order);
    if (moved_index.empty()) break;
    std::vector<RelaxJob> jobs;
    std::vector<std::pair<int, int>> job_key;
    for (const auto& [l, o] : targets) {
      const OrthantWork& w = orthants[position.at(l)];
      if (!moved_index.count(l)) continue;  // moved orthants are live
      jobs.push_back({&w, objectives[o], options.order, outcomes.at({l, o}).working_set, 0,
                      StopBeyond(witnessed, o)});
      job_key.push_back({l, o});
    }
    ctx.progress.Phase("order " + std::to_string(options.order) +
                           (options.every_endpoint ? " again in the box of its own bounds"
                                                   : " again where a solve stopped short"),
                       static_cast<int>(jobs.size()));
    const auto outs = RunRelaxationJobs(ctx, jobs, orthants);
    result.jobs_run += static_cast<int>(jobs.size());
    for (std::size_t i = 0; i < jobs.size(); ++i) {
      JobOutcome& kept = outcomes.at(job_key[i]);
      const JobOutcome& again = outs[i];
      const int dir = objectives[job_key[i].second].dir;
      // Infeasible: the orthant is empty (RunRelaxationJobs recorded the certificate). Solved: both bounds hold,
      // the tighter one is kept.
      const bool valid =
          again.status == JobStatus::kSolved && (!verify_on || again.verification == sdp::VerifyStatus::kVerified);
      if (again.status == JobStatus::kInfeasible || (valid && Beyond(-dir, again.bound, kept.bound))) {
        kept = again;
        ++result.bounds_tightened;
      }
    }
  }
  return result;
}

}  // namespace hw::dss
