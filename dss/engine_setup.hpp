#pragma once
// Where the caller's BoundsOptions become what the engine's core reads, once per run (in the manner of Ceres'
// PreprocessedProblem): the settings every stage and job shares (EngineSettings) and one option struct per stage.
// Only the orchestrator (dss/set_membership.cpp) uses this; the stages never see BoundsOptions.
#include "dss/aggregate.hpp"
#include "dss/bounds_options.hpp"
#include "dss/cheap_pass.hpp"
#include "dss/edge_witness.hpp"
#include "dss/engine_settings.hpp"
#include "dss/full_pass.hpp"
#include "dss/moment_witness.hpp"
#include "dss/orthant_screen.hpp"
#include "dss/refine_pass.hpp"

namespace hw::dss {

// The shared settings, with the engine-wide SDP settings applied to the caller's generation options.
EngineSettings ToEngineSettings(const BoundsOptions& options);

// Each stage's options for a run at horizon `horizon` (which sets the cheap order).
struct StageOptions {
  ScreenOptions screen;               // 1. screen orthants
  EdgeWitnessOptions edge_witness;    // 3. edge witnesses
  CheapPassOptions cheap;             // 4. cheap pass (its order is the cheap order)
  bool contract_before_full_pass = true;
  FullPassOptions full;               // 5. full pass, when full.order > cheap.order
  RefinePassOptions stopped_short;    // 6. endpoints of solves that stopped short
  RefinePassOptions every_endpoint;   // 6b. every open endpoint (off by default)
  MomentWitnessOptions moment_witness;  // 7. moment witnesses
  AggregateOptions aggregate;         // 8. aggregate
  bool has_full_pass() const { return full.order > cheap.order; }
};
StageOptions ToStageOptions(const BoundsOptions& options, int horizon);

}  // namespace hw::dss
