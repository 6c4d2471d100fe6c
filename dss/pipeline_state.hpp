#pragma once
// The state the engine's stages hand on: the objectives, the live orthants and the outcomes so far. The
// orchestrator (dss/set_membership.cpp) creates it; each stage reads what the stages before it left and adds its
// own part.
#include <map>
#include <utility>
#include <vector>

#include "dss/engine_context.hpp"
#include "dss/job_outcome.hpp"

namespace hw::dss {

// (orthant index, objective index).
using ObjectiveKey = std::pair<int, int>;
// One pass's outcome per (orthant, objective).
using PassOutcomes = std::map<ObjectiveKey, JobOutcome>;

struct PipelineState {
  // Min and max of every parameter bounded (of every parameter when boxes are contracted); the wanted ones are
  // those of the reported intervals (indices into objectives).
  std::vector<Objective> objectives;
  std::vector<int> wanted_objectives;
  // The orthants the screen left, with their boxes and kept rows (stages contract boxes and prove orthants empty).
  std::vector<OrthantWork> orthants;
  // Stage 3 (edge witnesses): objectives settled without a relaxation job, and per objective the most extreme
  // value its parameter attains at a certified feasible point.
  PassOutcomes settled;
  std::map<int, double> witnessed;
  // Stage 4 (cheap pass, renumbered to the contracted boxes' rows) and stages 5-6 (full pass, refinements).
  PassOutcomes cheap;
  PassOutcomes full;
};

}  // namespace hw::dss
