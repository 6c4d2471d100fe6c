#pragma once
// The inner hull of D: for every parameter and both directions, a point of D (found by local optimisation over
// theta and the initial state) as extreme as a local search finds, each re-checked by CheckMembership. The
// hull of these points lies inside the exact interval, so outer/inner per parameter says how tight the
// outer bounds are.
#include <optional>
#include <string>
#include <vector>

#include "exact/lifted_lp.hpp"
#include "exact/lp_solver.hpp"

namespace hw::exact {

struct InnerHullOptions {
  int restarts = 2;                // extra local starts per objective from perturbed points of D
  double time_limit_seconds = 120; // over all objectives; what is found by then is reported
  bool IsValid(std::string* error) const;
};

struct InnerPoint {
  std::vector<double> theta;   // layout order
  double slack = 0.0;          // CheckMembership's slack (>= 0)
  std::string objective;       // e.g. "max alpha3", "start"
};

struct InnerHull {
  // Per parameter: the range over the certified points (absent when no point of D was found).
  std::vector<std::optional<std::pair<double, double>>> ranges;
  std::vector<InnerPoint> points;  // the certified points, the extreme ones per parameter
  int local_solves = 0;
  double seconds = 0.0;
};

// `start` is a point believed to be in (or near) D, e.g. the centre of a surviving box's LP solution or the
// truth of a simulation; `box` is a proven outer box of D (the search stays inside it).
InnerHull ComputeInnerHull(const LiftedData& data, const ParamBox& box, const std::vector<double>& start,
                           const InnerHullOptions& options, LpSolver& solver);

}  // namespace hw::exact
