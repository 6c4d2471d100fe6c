#pragma once
// Box contraction (bound tightening) between the engine's passes: every orthant's box shrinks to the verified
// bounds a pass found for its parameters. Those bounds hold for every point of the orthant's part of D^ss(n) in
// its box, so relaxations in the smaller box bound the same set: they stay valid, are at least as tight (the box
// constraints are tighter), and are better conditioned (a thin set in a wide box makes the moment matrices
// nearly singular; docs/setmembership_scale.md).
#include <set>
#include <vector>

#include "dss/cheap_pass.hpp"

namespace hw::dss {

// Contracts each orthant's box to the pass's verified bounds (any solved bound with verification off); returns
// the largest relative shrink of a side. Bounds that cross prove the orthant empty (at relaxation order `order`).
double ContractOrthantBoxes(EngineContext& ctx, const std::vector<Objective>& objectives, const PassOutcomes& pass,
                            std::vector<OrthantWork>& orthants, int order);

// Contracts the boxes of the live orthants whose indices are in `subset` to the verified bounds in `outcomes`,
// proves empty those whose bounds cross, reduces the rows of the orthants whose box moved in their new box, and
// renumbers the working sets in `outcomes` of those orthants to their new rows. Returns the moved orthants'
// indices. Orthants whose box did not move keep their rows.
std::set<int> ContractAndReduceRows(EngineContext& ctx, const std::vector<Objective>& objectives,
                                    PassOutcomes& outcomes, const std::set<int>& subset,
                                    std::vector<OrthantWork>& orthants, int order);

// Before the order-delta pass: contracts the boxes to the cheap pass's bounds (state.cheap), reduces every
// contracted orthant's rows again in its new box, and renumbers the working sets in state.cheap to the new rows
// (the full pass starts from them). Orthants whose box did not move keep their rows.
void ContractBeforeFullPass(EngineContext& ctx, PipelineState& state, int cheap_order);

}  // namespace hw::dss
