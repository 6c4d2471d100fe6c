#pragma once
// The settings the engine's stages and jobs read, converted once from the caller's BoundsOptions by the
// orchestrator (dss/set_membership.cpp, in the manner of Ceres' PreprocessedProblem): the engine's core never sees
// the public options, and a job reads the same settings in whichever process runs it.
#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

#include "dss/inner_points.hpp"
#include "dss/row_reduction_options.hpp"
#include "pop/constraint_generation.hpp"

namespace hw::dss {

struct EngineSettings {
  // Constraint generation of every relaxation job, with the engine-wide SDP settings applied; its order is set
  // per job.
  pop::ConstraintGenerationOptions generation;
  // The backend that solves the relaxations of order d is backends[d - 1] (the LP screen's is backends[0]).
  std::vector<std::string> backends;
  RowReductionOptions reduction;  // the exact reduction of data rows (reduce jobs)
  InnerPointOptions local_search;  // local searches of feasible points (witness jobs)
  // Progress lines from inside relaxation jobs (one per constraint-generation round); null = silent.
  std::function<void(const std::string&)> round_log;

  bool verify() const { return generation.verify.enabled; }
  const std::string& backend(int order) const {
    if (order < 1 || order > static_cast<int>(backends.size()))
      throw std::out_of_range("no backend for relaxation order " + std::to_string(order));
    return backends[order - 1];
  }
};

}  // namespace hw::dss
