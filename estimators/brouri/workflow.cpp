#include "estimators/brouri/workflow.hpp"

namespace hw::brouri {

WorkflowConfig WorkflowConfig::Paper() {
  WorkflowConfig c;
  c.steps = MakeStepPlan({-0.6, -0.4, -0.2, 0.0, 0.2, 0.4, 0.6, 0.8, 1.0, 1.2},
                         {1.0, 0.8, 0.6, 0.4, 0.3, 0.0, -0.3, -0.6, -1.0, -1.2, -1.4}, -0.9, 0.5, 80.0, 100);
  c.omegas = {0.01, 0.02, 0.05, 0.1, 0.2};
  c.nonlinear.degree = 5;
  return c;
}

WorkflowResult RunWorkflow(const BacklashHwSystem& system, const WorkflowConfig& config, std::uint64_t seed) {
  WorkflowResult r;
  const auto& plan = config.steps;
  r.step_y = Simulate(system, plan.Input(), plan.sample_time, seed).y;
  r.nonlinear = EstimateFromSteps(plan, config.nonlinear, {}, r.step_y, &r.nonlinear_summary);
  r.sines = MakeSinePlan(r.nonlinear, config.omegas, config.amplitude, config.samples_per_period, config.periods,
                         config.settling_time);
  for (std::size_t i = 0; i < r.sines.experiments.size(); ++i) {
    const auto u = r.sines.Input(i);
    const auto y = Simulate(system, u, r.sines.experiments[i].sample_time(), seed + 1000 + i).y;
    Summary s;
    r.points.push_back(EstimateFromSine(r.sines, i, config.frequency, {}, y, &s));
    r.point_summaries.push_back(s);
  }
  UnwrapPhases(&r.points);
  return r;
}

std::vector<double> TrueHoldOutputs(const BacklashHwSystem& system, const StepPlan& plan) {
  const BacklashHwSystem n = system.Normalised();
  MemoryOperator f(n.kind, n.backlash);
  std::vector<double> out;
  for (double level : plan.Levels()) out.push_back(PolyEval(n.h, f.Step(level)));
  return out;
}

}  // namespace hw::brouri
