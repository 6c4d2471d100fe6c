#pragma once
// Inner witnesses for D^ss(n): feasible parameter points found by local optimisation.
//
// The relaxation gives OUTER bounds (every point of D^ss(n) lies inside them). A point p that satisfies every
// inequality of D^ss(n) in its own sign orthant, checked by plain evaluation (HwOuterSet::min_slack(p) >= 0),
// is an INNER witness: the exact interval of D^ss(n) reaches at least p_k. So for each parameter
//     [max inner witness min, min inner witness max]  ⊆  exact D^ss(n) interval  ⊆  relaxation interval,
// and the distance between the two brackets is what a higher relaxation order could still gain. Local
// optimisation (Ipopt, quasi-Newton, inequalities tightened by a margin so that the returned point is strictly
// feasible) finds the witnesses; it proves nothing about the outer side and may miss far parts of the set.
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "dss/hw_outer_set.hpp"

namespace hw::dss {

struct InnerPointOptions {
  int max_iterations = 500;
  double margin = 1e-7;  // inequalities g >= margin in the NLP (normalised constraints, scaled variables)
  bool IsValid(std::string* error) const;
};

struct InnerWitness {
  bool found = false;      // a point that passed min_slack(p) >= 0 in orthant `orthant`
  double value = 0.0;      // p_k, original units
  std::vector<double> point;  // original units
  double min_slack = 0.0;  // HwOuterSet::min_slack(point)
  int orthant = -1;
  std::string message;     // Ipopt's status, or why the point was rejected
};

// A point of D^ss(n) in orthant `orthant` checked by evaluating every inequality of that orthant with a
// rounding-error allowance (dss::CertifiedMinSlack >= 0): the exact interval of every parameter reaches it.
struct FeasiblePoint {
  int orthant = -1;
  std::vector<double> point;  // original units, inside the orthant's box
  double certified_min_slack = 0.0;
};

// `count` deterministic pseudo-random points in `box` (a fixed-seed 64-bit LCG: the same starts on every machine).
std::vector<std::vector<double>> PseudoRandomPointsInBox(const std::vector<std::pair<double, double>>& box,
                                                         int count, uint64_t seed);

// Locally extremises parameter k (dir = -1: min, +1: max) over D^ss(n) within orthant l and the prior box,
// starting from `start` (original units; need not be feasible). `rows` (optional, indices into
// data_constraints(l)) limits the NLP to those data rows, e.g. the rows kept by the exact reduction, which imply
// the others; the returned witness is checked against every row all the same.
InnerWitness LocalExtreme(const HwOuterSet& set, int l, int k, int dir, const std::vector<double>& start,
                          const InnerPointOptions& options = {}, const std::vector<int>* rows = nullptr);

}  // namespace hw::dss
