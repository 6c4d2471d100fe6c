#pragma once
// What a relaxation job is asked (an objective) and what it answers (JobOutcome), as every stage reads it.
#include <cstddef>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "dss/statuses.hpp"

namespace hw::dss {

// One objective: min (dir = -1) or max (dir = +1) of parameter `param`.
struct Objective {
  int param = 0;
  int dir = -1;
};

// A relaxation job's answer (bounds in original units).
struct JobOutcome {
  JobStatus status = JobStatus::kFailed;
  double bound = 0.0;
  bool tight = false;
  std::string message;
  int rounds = 0;
  int sdp_iterations = 0;
  double seconds = 0.0;
  std::size_t moments = 0, blocks = 0;
  std::vector<int> working_set;  // indices into the job's rows that had blocks in the last LMI
  std::vector<int> active_set;   // the part of it with non-negligible multipliers (warm start of other jobs)
  // bound is the verified value when verified, float_bound the solver's.
  sdp::VerifyStatus verification = sdp::VerifyStatus::kNotRun;
  double float_bound = 0.0, correction = 0.0, verify_seconds = 0.0;
  JobOrigin origin = JobOrigin::kNone;
  int bound_round = 0;
  bool unfinished = false;         // the bound is the verified last iterate of a solve that stopped short
  bool beyond_known_value = false; // ended once its bound passed stop_beyond: valid, cannot move the endpoint
  // The last solved round's first-order moments, original units (empty when no round solved): the relaxation's
  // guess of the extreme point, a start for a local search of a feasible point there (dss/moment_witness.hpp).
  std::vector<double> first_moments;
  nlohmann::json to_json() const;
  static JobOutcome from_json(const nlohmann::json& j);
};

}  // namespace hw::dss
