#pragma once
// Stage 8 of the bound engine: the intervals (paper 001, eqs. 31-33). Each endpoint is the most extreme orthant
// bound over the orthants not proven empty; a job that failed at full order falls back to its orthant's cheap
// bound, then to the orthant's box edge (both valid, marked "conservative"). Every interval is intersected with
// the prior box, which is an assumption of every result.
#include <map>
#include <string>
#include <vector>

#include "dss/pipeline_state.hpp"

namespace hw::dss {

struct AggregateOptions {
  bool verify = true;
  int order = 3;
  int cheap_order = 2;
};

struct AggregateResult {
  std::vector<ParameterInterval> intervals;
  // Where the orthant bounds entering the endpoints came from (dss/statuses.hpp).
  std::map<BoundSource, int> sources;
  bool clipped_to_box = false;  // some endpoint was intersected with the prior box
};

AggregateResult AggregateIntervals(const AggregateOptions& options, const HwOuterSet& set,
                                   const std::vector<Objective>& objectives, const std::vector<int>& wanted_params,
                                   const PassOutcomes& cheap, const PassOutcomes& full,
                                   const std::vector<OrthantWork>& orthants);

}  // namespace hw::dss
