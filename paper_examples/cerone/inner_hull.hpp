#pragma once
// The inner hull of D^ss(n): per parameter, [min, max] over certified feasible points (inner witnesses).
//
// Every witness p satisfies every inequality of its own sign orthant, checked by evaluation with a rounding
// allowance (dss::CertifiedMinSlack >= 0) and lies in the prior box, so the exact D^ss(n) interval, and every
// valid outer interval at any relaxation order, contains the inner hull. The witnesses come from local
// optimisation (dss::LocalExtreme) of each wanted parameter in both directions, started from
//   1. the truth (in the truth's orthant),
//   2. deterministic pseudo-random points in the hull found so far, widened by `spread` (in each start's orthant),
//   3. the witness most extreme in the objective's parameter, when another objective's search found it or it
//      was given (e.g. the bound engine's certified feasible points, dss::BoundsSummary::feasible_points);
// a local search from one start misses far parts of a thin set, so the hull is only ever a lower bound of the
// exact interval.
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "dss/hw_outer_set.hpp"
#include "dss/inner_points.hpp"

namespace hw::cerone {

struct InnerHullOptions {
  int random_starts = 2;   // per objective (parameter and direction)
  int restart_rounds = 1;  // rounds of restarts from other objectives' more extreme witnesses
  double spread = 0.1;     // random starts in the hull box widened by this fraction of its width on each side
  uint64_t seed = 1;       // of the starts (deterministic on every machine)
  dss::InnerPointOptions local;
  bool IsValid(std::string* error) const;
};

struct Witness {
  std::vector<double> point;  // original units, inside the prior box
  int orthant = -1;
  double certified_slack = 0.0;  // dss::CertifiedMinSlack at the point, >= 0
};

struct InnerInterval {
  std::string name;
  int param = 0;       // index in the set's layout
  bool found = false;  // at least one witness (the hull is empty otherwise)
  double lower = 0.0, upper = 0.0;
  Witness lower_witness, upper_witness;  // points attaining lower and upper
  double half_width() const { return 0.5 * (upper - lower); }
};

struct InnerHull {
  std::vector<InnerInterval> intervals;  // the wanted parameters, in layout order
  int witnesses = 0;                     // certified points found (truth and given points included)
  int given_witnesses = 0;               // given points that certified
  int local_solves = 0;
  double seconds = 0.0;
};

// The point clipped to the prior box, with its orthant and certified slack; an empty point when it is not a
// certified feasible point of its orthant.
Witness CertifyWitness(const dss::HwOuterSet& set, std::vector<double> point);

// The inner hull of the parameters `params` (layout indices; empty = all) from `truth` (need not be feasible)
// and the points `given` (each enters when it certifies, and is a restart point like any witness). `progress`
// gets a line after each stage and at most every 10 s within one (at N = 1000 a hull takes minutes).
InnerHull ComputeInnerHull(const dss::HwOuterSet& set, const std::vector<double>& truth,
                           const std::vector<int>& params, const InnerHullOptions& options = {},
                           const std::vector<std::vector<double>>& given = {},
                           const std::function<void(const std::string&)>& progress = {});

}  // namespace hw::cerone
