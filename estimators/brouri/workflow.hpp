#pragma once
// End-to-end run of Brouri's two stages on a simulated system: plan -> simulate -> estimate.
// Used by the paper reproduction, the tests and `hwbounds brouri simulate`.
#include <cstdint>
#include <vector>

#include "estimators/brouri/experiment.hpp"

namespace hw::brouri {

struct WorkflowConfig {
  StepPlan steps;
  std::vector<double> omegas;
  double amplitude = 1.0;
  int samples_per_period = 512;
  int periods = 50;             // N of eq. 23
  double settling_time = 80.0;  // s, used to size the discarded transient of each sine
  NonlinearOptions nonlinear;
  FrequencyOptions frequency;
  // The paper's Section 6 experiment: reset -0.9, ascending -0.6 .. 1.2 (j_a = 4 for the paper's system),
  // descending 1.0 .. -1.4 with the U_j of Table 1 (j_d = 5), Ts = 0.5 s, M = 100, p = 5;
  // sines U = 1 at omega = 0.01 .. 0.2 rad/s, N = 50.
  static WorkflowConfig Paper();
};

struct WorkflowResult {
  std::vector<double> step_y;
  NonlinearEstimate nonlinear;
  Summary nonlinear_summary;
  SinePlan sines;
  std::vector<FrequencyPoint> points;
  std::vector<Summary> point_summaries;
};

// Stage 1 on `system`, then stage 2 through the pre-compensator built from the stage-1 estimate.
WorkflowResult RunWorkflow(const BacklashHwSystem& system, const WorkflowConfig& config, std::uint64_t seed);

// Steady-state noise-free X_j = h(F[U_j]) of every planned hold (reset, ascending, descending).
std::vector<double> TrueHoldOutputs(const BacklashHwSystem& system, const StepPlan& plan);

}  // namespace hw::brouri
