#pragma once
// The exact-set engine's jobs as text, so that fork workers and MPI ranks can run them: a box's emptiness
// test ("empty") and one endpoint's refinement ("objective"). Specs and answers are JSON; a spec's hash names
// its answer in the run directory, so a rerun reads what is done.
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "exact/branch_and_bound.hpp"
#include "sdp/job_executor.hpp"

namespace hw::exact {

struct ExactJobSettings {
  std::string lp_solver = "ipm";
  BoxEvaluationOptions evaluation;
  ObjectiveSearchOptions search;
};

// `cheap_windows`: try the cheap windows first (the pruning search stops once a level prunes nothing with them).
nlohmann::json EmptinessJobSpec(const ParamBox& box, const LpBasis& warm, bool cheap_windows);
nlohmann::json ObjectiveJobSpec(const ParamBox& start, const std::vector<ParamBox>& boxes, const Objective& objective,
                                std::optional<double> target, double target_gap,
                                const std::vector<ParameterForm>& forms = {},
                                std::optional<int> lp_budget = std::nullopt,  // default: the settings' budget
                                const std::optional<ParamBox>& scale = std::nullopt);  // see SearchObjective

// Answers either kind of spec (called in the worker process).
sdp::JobFunction MakeExactJobFunction(const LiftedData& data, const ExactJobSettings& settings);

// An "empty" job's answer.
struct EmptinessAnswer {
  BoxVerdict verdict = BoxVerdict::kKept;
  std::optional<PruneCertificate> certificate;
  std::vector<double> point;
  LpBasis basis;
  int lps = 0, lp_failures = 0;
  static EmptinessAnswer from_json(const nlohmann::json& j);
};

std::string EncodeBasis(const LpBasis& basis);
LpBasis DecodeBasis(const std::string& text);
// A stable 64-bit FNV-1a hash of a spec, in hex: the job's name in the run directory.
std::string JobKey(const std::string& spec);

}  // namespace hw::exact
