#pragma once
// Stage 6 of the bound engine (after the full pass): endpoints that rest on a solve that stopped short.
//
// On a thin set in a wide box the LMIs are ill-conditioned: a round may end in CSDP "partial success" or SDPA
// pFEAS, and the job's bound is then the verified bound of its last iterate (valid, but looser than the
// relaxation's). Where such a bound is an interval's endpoint, its orthant's box is contracted to the verified
// bounds of the full pass (every point of the orthant in the old box lies in the new one), the orthant's rows are
// reduced again, and the job runs again there: same set, better conditioned. The tighter of the two verified
// bounds is kept (both hold), so the endpoints can only move inward and never exclude a point of D^ss(n).
#include <map>
#include <utility>
#include <vector>

#include "dss/cheap_pass.hpp"

namespace hw::dss {

struct RefinePassOptions {
  int order = 3;
  int passes = 1;  // contraction-and-solve rounds (0: off)
  bool every_endpoint = false;  // every open endpoint, not only those resting on a solve that stopped short
};

struct RefinePassResult {
  int passes_run = 0;
  int jobs_run = 0;
  int bounds_tightened = 0;
};

// (orthant, objective) pairs among `wanted` whose outcome stopped short (JobOutcome::unfinished, solved) and is
// the endpoint: no other live orthant's solved or skipped bound of the objective lies beyond it. Ascending order.
std::vector<std::pair<int, int>> StoppedShortEndpoints(const std::vector<Objective>& objectives,
                                                       const std::vector<int>& wanted, const PassOutcomes& full,
                                                       const std::vector<OrthantWork>& orthants);

// (orthant, objective) pairs among `wanted` whose solved outcome is the endpoint and lies beyond the value a
// certified feasible point attains (`witnessed`, per objective), by more than 1e-6 * max(1, |value|).
std::vector<std::pair<int, int>> OpenEndpoints(const std::vector<Objective>& objectives, const std::vector<int>& wanted,
                                               const PassOutcomes& full, const std::vector<OrthantWork>& orthants,
                                               const std::map<int, double>& witnessed);

// Refines the wanted endpoints in state.full (the refined outcomes replace the full pass's in place).
RefinePassResult RefineEndpoints(const RefinePassOptions& options, EngineContext& ctx, PipelineState& state);

}  // namespace hw::dss
