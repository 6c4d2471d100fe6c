#pragma once
// Options of the edge-witness stage (dss/edge_witness.hpp), apart so that BoundsOptions can hold them.
#include <string>

#include "dss/inner_points.hpp"

namespace hw::dss {

struct EdgeWitnessOptions {
  bool enabled = true;
  // Below this relaxation order the SDP jobs cost milliseconds (order 1 gives the box edges for these
  // problems), far less than the local searches; the stage then does not run.
  int min_order = 2;
  int random_starts = 3;  // deterministic starts in the orthant's box when no feasible point is known yet
  // A witness attains the edge when |p_k - edge| <= edge_tolerance * box width (it is then moved onto it).
  double edge_tolerance = 1e-8;
  // Relaxation jobs end once their bound passes the value a certified feasible point attains (in any orthant):
  // such a bound cannot move the endpoint (PipelineState::witnessed). Off: every job runs to convergence.
  bool stop_beyond_witnesses = true;
  InnerPointOptions local;
  bool IsValid(std::string* error) const;
};

}  // namespace hw::dss
