#include "dss/engine_setup.hpp"

#include <algorithm>

namespace hw::dss {

EngineSettings ToEngineSettings(const BoundsOptions& options) {
  EngineSettings settings;
  settings.generation = options.generation;
  auto& sdp = settings.generation.sdp;
  // In scaled coordinates every feasible moment vector has |y_alpha| <= 1, so a multiplier X >= 0 with
  // sum_i |F_i . X| < F_0 . X already proves emptiness; 0.5 leaves a margin.
  sdp.infeasibility_tolerance = std::max(sdp.infeasibility_tolerance, 0.5);
  // Endpoints come from the dual side, whose validity needs dual feasibility, not a small gap: accept
  // near-optimal stops up to 1e-5 (the gap costs at most that much tightness on the scaled parameters).
  sdp.acceptable_gap = std::max(sdp.acceptable_gap, 1e-5);
  // The engine's own fallbacks (the other backend, then the verified bounds of the rounds) follow a failed
  // round, so a second SDPA attempt with other parameters would only add a full solve to each failing round.
  sdp.retry_with_default_parameters = false;
  for (int d = 1; d <= kMaxOrder; ++d)
    settings.backends.push_back(SolverForOrder(options.solver, d, options.generation.block_order_cap));
  settings.reduction = options.reduction;
  settings.local_search = options.edge_witness.local;
  settings.round_log = options.round_log;
  return settings;
}

StageOptions ToStageOptions(const BoundsOptions& options, int horizon) {
  // Order 1 (Shor) returns the box edges for these problems, so the cheap order is at least 2 (and at least the
  // minimal order of Remark 3, ceil((n + 1) / 2)); with nothing cheaper than the target order there is no separate
  // cheap pass.
  const int cheap_order =
      options.cheap_pass ? std::min(options.order, std::max(MinimalOrder(horizon), 2)) : options.order;
  StageOptions stages;
  stages.screen = ScreenOptions{options.lp_screen};
  stages.edge_witness = options.edge_witness;
  stages.edge_witness.enabled = options.edge_witness.enabled && options.order >= options.edge_witness.min_order;
  stages.cheap = CheapPassOptions{cheap_order, options.contraction_passes, options.contraction_min_shrink,
                                  options.contraction_max_rounds};
  stages.contract_before_full_pass = options.contract_before_full_pass;
  stages.full = FullPassOptions{options.order, cheap_order};
  stages.stopped_short = RefinePassOptions{options.order, options.stopped_short_refinements, false};
  stages.every_endpoint = RefinePassOptions{options.order, options.endpoint_refinements, true};
  // Not below the edge-witness stage's order: there the SDP jobs cost less than the local searches.
  stages.moment_witness =
      MomentWitnessOptions{options.moment_witnesses && options.order >= options.edge_witness.min_order, options.order};
  stages.aggregate = AggregateOptions{options.generation.verify.enabled, options.order, cheap_order};
  return stages;
}

}  // namespace hw::dss
