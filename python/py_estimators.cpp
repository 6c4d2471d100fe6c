// hwbounds.esmaeilani_estimate and hwbounds.brouri_estimate: the point-estimate baselines, as the CLI runs them.
#include <algorithm>
#include <cmath>
#include <filesystem>

#include <fmt/format.h>

#include "estimators/brouri/experiment.hpp"
#include "estimators/esmaeilani/estimator.hpp"
#include "python/py_convert.hpp"
#include "python/py_module.hpp"

namespace hw::python {
namespace {

// One recording, or a list of them (a plain list of numbers is not a list of recordings).
std::vector<py::handle> RecordingList(py::handle h) {
  if (py::isinstance<py::list>(h)) {
    std::vector<py::handle> out;
    for (auto item : h) out.push_back(item);
    return out;
  }
  return {h};
}

nlohmann::json SummaryJson(const esmaeilani::Summary& s) {
  const char* status = s.status == esmaeilani::Summary::Status::kConverged       ? "converged"
                       : s.status == esmaeilani::Summary::Status::kMaxIterations ? "max_iterations"
                                                                                 : "failed";
  nlohmann::json j = {{"status", status},
                      {"message", s.message},
                      {"iterations", s.iterations},
                      {"unknowns", s.unknowns},
                      {"equations", s.equations},
                      {"constraints", s.constraints},
                      {"initial_cost", s.initial_cost},
                      {"final_cost", s.final_cost},
                      {"cost_history", s.cost_history},
                      {"seconds", s.seconds},
                      {"qp_seconds", s.qp_seconds},
                      {"censored_samples", s.censored_samples}};
  if (s.output_error.ran) {
    const auto& oe = s.output_error;
    j["output_error"] = {{"message", oe.message},
                         {"improved", oe.improved},
                         {"iterations", oe.iterations},
                         {"initial_cost", oe.initial_cost},
                         {"final_cost", oe.final_cost},
                         {"seconds", oe.seconds},
                         {"max_constraint_violation", oe.max_constraint_violation}};
  }
  return j;
}

// Fit figures of a validation segment, simulated as `hwbounds esmaeilani --validate` does.
nlohmann::json ValidationJson(const esmaeilani::EsmaeilaniModel& m, const esmaeilani::Segment& s, bool clamp) {
  const auto yh = m.Simulate(s.u, {}, clamp);
  double max_error = 0.0;
  for (std::size_t i = 0; i < yh.size(); ++i) max_error = std::max(max_error, std::abs(s.y[i] - yh[i]));
  return {{"name", s.name},
          {"fit_percent", fit_percent(s.y, yh)},
          {"rmse", rmse(s.y, yh)},
          {"max_error", max_error},
          {"y_hat", yh}};
}

std::vector<esmaeilani::Segment> Segments(py::handle h, const std::string& what) {
  std::vector<esmaeilani::Segment> out;
  const auto items = RecordingList(h);
  for (std::size_t i = 0; i < items.size(); ++i) {
    const std::string name =
        py::isinstance<py::str>(items[i]) ? items[i].cast<std::string>() : fmt::format("{}[{}]", what, i);
    const CsvTable t = RecordingFromPython(items[i], name, {"u", "y"}, {"t"});  // t: checked, not used
    out.push_back({t.column("u"), t.column("y"), name});
  }
  return out;
}

py::object EsmaeilaniEstimate(py::handle segments, const esmaeilani::Options& options, py::handle constraints,
                              py::handle validate) {
  RequireValid(options);
  const auto segs = Segments(segments, "segments");
  esmaeilani::Constraints cons;
  if (!constraints.is_none())
    cons = py::isinstance<py::str>(constraints) ? esmaeilani::Constraints::Load(constraints.cast<std::string>())
                                                : esmaeilani::Constraints::FromJson(ToJson(constraints), "constraints");
  const auto valid = validate.is_none() ? std::vector<esmaeilani::Segment>{} : Segments(validate, "validate");
  esmaeilani::Summary sum;
  const auto m = WithoutGil([&] { return esmaeilani::Estimate(options, segs, cons, &sum); });
  if (!sum.ok()) throw std::runtime_error("esmaeilani: estimation failed: " + sum.message);
  nlohmann::json out = {{"model", esmaeilani::ModelFileJson(m, options, cons, sum)},
                        {"summary", SummaryJson(sum)},
                        {"validation", nlohmann::json::array()}};
  for (const auto& s : valid) out["validation"].push_back(ValidationJson(m, s, options.clamp_output));
  return ToPython(out);
}

// Brouri: the plan (dict or plan.json path) and its recordings (one for stage 1, one per sine for stage 2;
// None = the files the plan names, next to plan.json).
py::object BrouriEstimate(py::handle plan_arg, py::handle recordings, const brouri::NonlinearOptions& nonlinear,
                          const brouri::FrequencyOptions& frequency) {
  RequireValid(nonlinear);
  RequireValid(frequency);
  const nlohmann::json j = JsonFromPython(plan_arg, "JSON file");  // as `brouri estimate --plan`
  const std::string stage =
      brouri::PlanStage(j, py::isinstance<py::str>(plan_arg) ? plan_arg.cast<std::string>() : "plan");
  const std::filesystem::path dir =
      py::isinstance<py::str>(plan_arg) ? std::filesystem::path(plan_arg.cast<std::string>()).parent_path() : "";
  if (recordings.is_none() && !py::isinstance<py::str>(plan_arg))
    throw py::value_error(
        "recordings: needed when the plan is a dict (the plan's file names are relative to plan.json)");
  auto recording = [&](std::size_t i, std::size_t count, const std::string& file, double ts) {
    if (recordings.is_none()) return brouri::ReadRecording((dir / file).string(), ts, "y");
    const auto items = RecordingList(recordings);
    if (items.size() != count)
      throw py::value_error(fmt::format("recordings: {} given; the plan has {} experiment{}", items.size(), count,
                                        count == 1 ? "" : "s"));
    return brouri::CheckRecording(RecordingFromPython(items[i], fmt::format("recordings[{}]", i), {"y"}, {"u", "t"}),
                                  ts, "y");
  };
  if (stage == "steps") {
    const auto plan = brouri::StepPlan::from_json(j);
    const auto rec = recording(0, 1, plan.file, plan.sample_time);
    brouri::Summary s;
    const auto est = WithoutGil([&] { return brouri::EstimateFromSteps(plan, nonlinear, rec.u, rec.y, &s); });
    return ToPython(brouri::StepsResultJson(est, s));
  }
  const auto plan = brouri::SinePlan::from_json(j);
  std::vector<brouri::FrequencyPoint> points;
  for (std::size_t i = 0; i < plan.experiments.size(); ++i) {
    const auto& e = plan.experiments[i];
    const auto rec = recording(i, plan.experiments.size(), e.file, e.sample_time());
    brouri::Summary s;
    points.push_back(WithoutGil([&] { return brouri::EstimateFromSine(plan, i, frequency, rec.u, rec.y, &s); }));
  }
  brouri::UnwrapPhases(&points);
  return ToPython(brouri::SinesResultJson(plan, points));
}

}  // namespace

void DefineEstimators(py::module_& m) {
  const esmaeilani::Options e;
  m.def(
      "esmaeilani_estimate",
      [](py::handle segments, int order, int grid_f, int grid_g, double weight_state, double weight_output,
         double weight_noise, int max_iterations, double relative_decrease, double damping, bool clamp_output,
         bool reproject, bool estimate_output_offset, bool refine_output_error, int oe_max_iterations,
         bool oe_estimate_initial_states, py::handle constraints, py::handle validate) {
        esmaeilani::Options o;
        o.order = order;
        o.grid_f = grid_f;
        o.grid_g = grid_g;
        o.weight_state = weight_state;
        o.weight_output = weight_output;
        o.weight_noise = weight_noise;
        o.max_iterations = max_iterations;
        o.relative_decrease = relative_decrease;
        o.damping = damping;
        o.clamp_output = clamp_output;
        o.reproject = reproject;
        o.estimate_output_offset = estimate_output_offset;
        o.refine_output_error = refine_output_error;
        o.oe_max_iterations = oe_max_iterations;
        o.oe_estimate_initial_states = oe_estimate_initial_states;
        return EsmaeilaniEstimate(segments, o, constraints, validate);
      },
      R"doc(Esmaeilani et al. 2020 constrained least squares / SQP (paper 002), as `hwbounds esmaeilani`.
segments: one recording or a list (each a spec string, {"u": array, "y": array} or (u, y)), each with its own
initial condition. Options mirror esmaeilani::Options. constraints: known-information dict or JSON path.
validate: recordings to report fit on. Returns {"model": the model JSON the CLI writes (usable by simulate),
"summary": {...}, "validation": [{name, fit_percent, rmse, max_error, y_hat}]}.)doc",
      py::arg("segments"), py::kw_only(), py::arg("order") = e.order, py::arg("grid_f") = e.grid_f,
      py::arg("grid_g") = e.grid_g, py::arg("weight_state") = e.weight_state,
      py::arg("weight_output") = e.weight_output, py::arg("weight_noise") = e.weight_noise,
      py::arg("max_iterations") = e.max_iterations, py::arg("relative_decrease") = e.relative_decrease,
      py::arg("damping") = e.damping, py::arg("clamp_output") = e.clamp_output, py::arg("reproject") = e.reproject,
      py::arg("estimate_output_offset") = e.estimate_output_offset,
      py::arg("refine_output_error") = e.refine_output_error, py::arg("oe_max_iterations") = e.oe_max_iterations,
      py::arg("oe_estimate_initial_states") = e.oe_estimate_initial_states, py::arg("constraints") = py::none(),
      py::arg("validate") = py::none());

  const brouri::NonlinearOptions n;
  const brouri::FrequencyOptions f;
  m.def(
      "brouri_estimate",
      [](py::handle plan, py::handle recordings, int degree, int max_degree, double plateau_sigmas,
         double plateau_abs_tol, const std::string& down_border, bool joint_refit, int harmonic, bool zoh_correction) {
        brouri::NonlinearOptions no;
        no.degree = degree;
        no.max_degree = max_degree;
        no.plateau_sigmas = plateau_sigmas;
        no.plateau_abs_tol = plateau_abs_tol;
        no.down_border = brouri::DownBorderMethodFromString(down_border);
        no.joint_refit = joint_refit;
        brouri::FrequencyOptions fo;
        fo.harmonic = harmonic;
        fo.zoh_correction = zoh_correction;
        return BrouriEstimate(plan, recordings, no, fo);
      },
      R"doc(Brouri's frequency method (paper 000), as `hwbounds brouri estimate`. plan: the plan dict or the
path of plan.json (`hwbounds brouri plan`); recordings: stage 1 one recording, stage 2 a list with one per
sine (spec strings, {"y": array[, "u": ..., "t": ...]} or (y,)); None reads the files the plan names next to
plan.json. Options mirror brouri::NonlinearOptions (stage 1) and FrequencyOptions (stage 2). Returns the
result JSON the CLI writes.)doc",
      py::arg("plan"), py::arg("recordings") = py::none(), py::kw_only(), py::arg("degree") = n.degree,
      py::arg("max_degree") = n.max_degree, py::arg("plateau_sigmas") = n.plateau_sigmas,
      py::arg("plateau_abs_tol") = n.plateau_abs_tol, py::arg("down_border") = brouri::ToString(n.down_border),
      py::arg("joint_refit") = n.joint_refit, py::arg("harmonic") = f.harmonic,
      py::arg("zoh_correction") = f.zoh_correction);
}

}  // namespace hw::python
