#pragma once
// Stage 7 of the bound engine (after the last pass): feasible points where the relaxations point.
//
// A relaxation job's last solved round has first-order moments E[x]; where the relaxation is nearly exact they lie
// near the extreme point of its objective. A local search of the same objective in the same orthant started there
// (dss::LocalExtreme, as a witness job: cached, run by the executor) often reaches a feasible point at or near
// the relaxation's bound, far from where searches around a known point end. Each point found is checked by
// evaluating every inequality of its orthant (CertifiedMinSlack), so the exact interval of D^ss(n) reaches it:
// the interval's witnessed range (ParameterInterval::witnessed_lower/upper) then says how much of the outer
// interval the relaxation may still overestimate. The bounds themselves do not change.
#include <vector>

#include "dss/pipeline_state.hpp"
#include "dss/inner_points.hpp"

namespace hw::dss {

struct MomentWitnessOptions {
  bool enabled = true;
  int order = 3;  // the order of the pass whose outcomes are given (part of the cache keys)
};

struct MomentWitnessResult {
  std::vector<FeasiblePoint> feasible_points;  // certified, one per (orthant, objective) whose search found one
  int jobs = 0;                                // local searches started (one per solved outcome with moments)
  int local_solves = 0;
  double seconds = 0.0;
};

// One witness job per wanted objective and live orthant whose outcome in state.full is "solved" with first
// moments, started from them (clipped to the orthant's box).
MomentWitnessResult FeasiblePointsFromMoments(const MomentWitnessOptions& options, EngineContext& ctx,
                                              const PipelineState& state);

}  // namespace hw::dss
