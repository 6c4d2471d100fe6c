#pragma once
// The exact set after the outer set: stage 1 (the D^ss(n) engine, dss/set_membership.hpp) proves a box,
// stage 2 (exact/exact_bounds.hpp) bounds D inside it. Shared by the CLI and the Python module.
#include <vector>

#include <nlohmann/json.hpp>

#include "exact/exact_bounds.hpp"
#include "dss/set_membership.hpp"

namespace hw::exact {

// The start box: the D^ss(n) intervals (valid bounds, also where conservative) within the prior box; the prior
// box for parameters the run did not bound.
ParamBox StartBoxFromOuter(const dss::BoundsSummary& outer, const dss::HwOuterSet& set);

// The exact run's JSON: "set": "exact", its intervals and counts, the stage-1 intervals under
// "outer_set_intervals", and the keys of the stage-1 JSON that describe the input (data, structure, warnings).
nlohmann::json ExactResultJson(const ExactBoundsSummary& exact, const nlohmann::json& outer_json,
                               const dss::BoundsSummary& outer, const std::vector<double>& truth);

}  // namespace hw::exact
