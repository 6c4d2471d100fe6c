#pragma once
// Stage 5 of the bound engine: the wanted objectives at the full order delta. Per objective, orthants are
// solved in order of their cheap bound, most extreme first, in waves (one orthant per objective per wave); an
// orthant whose cheap bound cannot move the aggregated endpoint is skipped: its order-delta bound is at least as
// tight as its cheap one (Property 3). The intervals equal those of solving every orthant at order delta.
// A job starts from the blocks of its own cheap job and of the orthant's full-order jobs of earlier waves (never
// of the same wave), so the numbers do not depend on which job finished first.
#include <vector>

#include "dss/cheap_pass.hpp"

namespace hw::dss {

struct FullPassOptions {
  int order = 3;
  int cheap_order = 2;
};

// Sets state.full to the outcomes at full order for the wanted objectives, from state.cheap; orthants skipped
// keep their cheap outcome with status "skipped" (its bound is valid and cannot move the interval). state.settled
// outcomes (dss/edge_witness.hpp) are exact at every order and are kept as given; state.witnessed values (see
// RunCheapPass) let jobs end early and skip orthants whose cheap bound is already beyond them.
void RunFullPass(const FullPassOptions& options, EngineContext& ctx, PipelineState& state);

}  // namespace hw::dss
