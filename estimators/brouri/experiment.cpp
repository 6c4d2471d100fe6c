#include "estimators/brouri/experiment.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "core/csv_table.hpp"
#include "core/recording.hpp"
#include "core/json_input.hpp"
#include "estimators/brouri/outliers.hpp"

namespace hw::brouri {

namespace {
bool Fail(std::string* error, std::string m) {
  if (error) *error = std::move(m);
  return false;
}
}  // namespace

bool StepPlan::IsValid(std::string* error) const {
  if (!(sample_time > 0)) return Fail(error, "sample_time must be positive");
  if (average_samples < 2) return Fail(error, "average_samples (M) must be >= 2");
  if (hold_samples <= average_samples)
    return Fail(error, fmt::format("hold_samples {} must exceed average_samples {} (the rest lets the transient die)",
                                   hold_samples, average_samples));
  if (levels_up.size() < 2) return Fail(error, "need at least 2 ascending levels");
  if (levels_down.size() < 2) return Fail(error, "need at least 2 descending levels");
  for (std::size_t j = 1; j < levels_up.size(); ++j)
    if (!(levels_up[j] > levels_up[j - 1]))
      return Fail(error, fmt::format("ascending levels must increase strictly (level {} = {} after {})", j + 1,
                                     levels_up[j], levels_up[j - 1]));
  if (!(levels_down.front() < levels_up.back()))
    return Fail(error, fmt::format("the first descending level {} must lie below the last ascending level {}",
                                   levels_down.front(), levels_up.back()));
  for (std::size_t j = 1; j < levels_down.size(); ++j)
    if (!(levels_down[j] < levels_down[j - 1]))
      return Fail(error, fmt::format("descending levels must decrease strictly (level {} = {} after {})", j + 1,
                                     levels_down[j], levels_down[j - 1]));
  if (!(reset_level < levels_up.front()))
    return Fail(error, fmt::format("reset level {} must lie below the first ascending level {}", reset_level,
                                   levels_up.front()));
  return true;
}

std::vector<double> StepPlan::Levels() const {
  std::vector<double> out{reset_level};
  out.insert(out.end(), levels_up.begin(), levels_up.end());
  out.insert(out.end(), levels_down.begin(), levels_down.end());
  return out;
}

std::vector<double> StepPlan::Input() const {
  std::vector<double> u;
  for (double l : Levels()) u.insert(u.end(), hold_samples, l);
  return u;
}

nlohmann::json StepPlan::to_json() const {
  return {{"method", "brouri"},         {"stage", "steps"},
          {"sample_time", sample_time}, {"hold_samples", hold_samples},
          {"average_samples", average_samples}, {"reset_level", reset_level},
          {"levels_up", levels_up},     {"levels_down", levels_down},
          {"file", file}};
}

StepPlan StepPlan::from_json(const nlohmann::json& j) {
  return ParseValidated<StepPlan>("step plan", [&] {
    CheckKeys(j, {"method", "stage", "sample_time", "hold_samples", "average_samples", "reset_level", "levels_up",
                  "levels_down", "file"},
              "step plan");
    StepPlan p;
    p.sample_time = j.at("sample_time").get<double>();
    p.hold_samples = j.at("hold_samples").get<int>();
    p.average_samples = j.at("average_samples").get<int>();
    p.reset_level = j.at("reset_level").get<double>();
    p.levels_up = j.at("levels_up").get<std::vector<double>>();
    p.levels_down = j.at("levels_down").get<std::vector<double>>();
    p.file = j.value("file", std::string("steps.csv"));
    return p;
  });
}

StepPlan MakeStepPlan(std::vector<double> levels_up, std::vector<double> levels_down, double reset_level,
                      double sample_time, double settling_time, int average_samples) {
  if (!(settling_time > 0)) throw InputError("settling time must be positive");
  if (!(sample_time > 0)) throw InputError("sample time must be positive");
  StepPlan p;
  p.sample_time = sample_time;
  p.average_samples = average_samples;
  p.hold_samples = static_cast<int>(std::ceil(settling_time / sample_time - 1e-9)) + average_samples;
  p.reset_level = reset_level;
  p.levels_up = std::move(levels_up);
  p.levels_down = std::move(levels_down);
  std::string err;
  if (!p.IsValid(&err)) throw InputError("step plan: " + err);
  return p;
}

double SineExperiment::sample_time() const { return 2 * std::numbers::pi / omega / samples_per_period; }

bool SinePlan::IsValid(std::string* error) const {
  if (!(amplitude > 0)) return Fail(error, "sine amplitude must be positive");
  if (experiments.empty()) return Fail(error, "no frequencies in the sine plan");
  for (const auto& e : experiments) {
    if (!(e.omega > 0)) return Fail(error, fmt::format("frequency {} must be positive", e.omega));
    if (e.samples_per_period < 2 * nonlinear.degree + 2)
      return Fail(error, fmt::format("{} samples per period cannot resolve harmonic {} (need >= {})",
                                     e.samples_per_period, nonlinear.degree, 2 * nonlinear.degree + 2));
    if (e.periods < 1 || e.transient_periods < 0) return Fail(error, "periods must be >= 1, transient periods >= 0");
  }
  return true;
}

std::vector<double> SinePlan::Command(std::size_t i) const {
  const auto& e = experiments.at(i);
  std::vector<double> z(e.total_samples());
  for (int k = 0; k < e.total_samples(); ++k)
    z[k] = amplitude * std::sin(2 * std::numbers::pi * (k % e.samples_per_period) / e.samples_per_period);
  return z;
}

std::vector<double> SinePlan::Input(std::size_t i) const {
  MemoryOperator pre = nonlinear.Precompensator();
  auto u = Command(i);
  for (double& v : u) v = pre.Step(v);
  return u;
}

nlohmann::json SinePlan::to_json() const {
  nlohmann::json ex = nlohmann::json::array();
  for (const auto& e : experiments)
    ex.push_back({{"omega", e.omega},
                  {"sample_time", e.sample_time()},
                  {"samples_per_period", e.samples_per_period},
                  {"transient_periods", e.transient_periods},
                  {"periods", e.periods},
                  {"file", e.file}});
  return {{"method", "brouri"}, {"stage", "sines"}, {"amplitude", amplitude}, {"experiments", ex},
          {"nonlinear", nonlinear.to_json()}};
}

SinePlan SinePlan::from_json(const nlohmann::json& j) {
  return ParseValidated<SinePlan>("sine plan", [&] {
    CheckKeys(j, {"method", "stage", "amplitude", "experiments", "nonlinear"}, "sine plan");
    SinePlan p;
    p.amplitude = j.at("amplitude").get<double>();
    for (const auto& e : j.at("experiments")) {
      CheckKeys(e, {"omega", "sample_time", "samples_per_period", "transient_periods", "periods", "file"},
                "sine plan: experiments[]");
      SineExperiment x;
      x.omega = e.at("omega").get<double>();
      x.samples_per_period = e.at("samples_per_period").get<int>();
      x.transient_periods = e.at("transient_periods").get<int>();
      x.periods = e.at("periods").get<int>();
      x.file = e.at("file").get<std::string>();
      p.experiments.push_back(x);
    }
    p.nonlinear = NonlinearEstimate::from_json(j.at("nonlinear"));
    return p;
  });
}

SinePlan MakeSinePlan(const NonlinearEstimate& nonlinear, const std::vector<double>& omegas, double amplitude,
                      int samples_per_period, int periods, double settling_time) {
  if (!(settling_time >= 0)) throw InputError("settling time must be >= 0");
  SinePlan p;
  p.amplitude = amplitude;
  p.nonlinear = nonlinear;
  for (std::size_t i = 0; i < omegas.size(); ++i) {
    SineExperiment e;
    e.omega = omegas[i];
    e.samples_per_period = samples_per_period;
    e.periods = periods;
    const double period = 2 * std::numbers::pi / omegas[i];
    // At least one period: the pre-compensator needs one full cycle to lock onto both borders.
    e.transient_periods = std::max(1, static_cast<int>(std::ceil(settling_time / period - 1e-9)));
    e.file = fmt::format("sine_{}.csv", i);
    p.experiments.push_back(e);
  }
  std::string err;
  if (!p.IsValid(&err)) throw InputError("sine plan: " + err);
  return p;
}

NonlinearEstimate EstimateFromSteps(const StepPlan& plan, const NonlinearOptions& options, const std::vector<double>& u,
                                    const std::vector<double>& y, Summary* summary) {
  std::string err;
  if (!plan.IsValid(&err)) throw InputError("step plan: " + err);
  const auto levels = plan.Levels();
  if (!u.empty()) {
    const auto planned = plan.Input();
    for (std::size_t i = 0; i < std::min(u.size(), planned.size()); ++i)
      if (std::abs(u[i] - planned[i]) > 1e-6 * (1 + std::abs(planned[i])))
        throw InputError(fmt::format("recorded u[{}] = {} differs from the planned level {} (hold {})", i, u[i],
                                     planned[i], i / plan.hold_samples));
  }
  const std::size_t need = levels.size() * static_cast<std::size_t>(plan.hold_samples);
  if (y.size() < need) {
    const std::size_t hold = y.size() / plan.hold_samples;
    throw InputError(fmt::format("step recording too short: {} samples, the plan needs {} ({} holds x {}); it stops "
                                 "in hold {} of {} (level {}) - record the remaining {:.6g} s",
                                 y.size(), need, levels.size(), plan.hold_samples, hold + 1, levels.size(),
                                 levels[std::min(hold, levels.size() - 1)], (need - y.size()) * plan.sample_time));
  }
  const auto holds = AverageHolds(y, levels, plan.hold_samples, plan.average_samples);
  const std::size_t nu = plan.levels_up.size();
  std::vector<HoldAverage> up(holds.begin() + 1, holds.begin() + 1 + nu), down(holds.begin() + 1 + nu, holds.end());
  NonlinearEstimate est;
  EstimateNonlinearities(options, holds.front(), up, down, &est, summary);
  return est;
}

namespace {
std::vector<std::size_t> OneBased(std::vector<std::size_t> v) {
  for (auto& i : v) ++i;
  return v;
}
}  // namespace

FrequencyPoint EstimateFromSine(const SinePlan& plan, std::size_t i, const FrequencyOptions& options,
                                const std::vector<double>& u, const std::vector<double>& y, Summary* summary) {
  const auto& e = plan.experiments.at(i);
  if (!u.empty()) {
    const auto planned = plan.Input(i);
    for (std::size_t k = 0; k < std::min(u.size(), planned.size()); ++k)
      if (std::abs(u[k] - planned[k]) > 1e-6 * (1 + std::abs(planned[k])))
        throw InputError(fmt::format("{}: recorded u[{}] = {} differs from the planned pre-compensated input {}", e.file,
                                     k, u[k], planned[k]));
  }
  if (y.size() < static_cast<std::size_t>(e.total_samples()))
    throw InputError(fmt::format("{} (omega = {}): {} samples recorded, the plan needs {} ({} transient + {} averaged "
                                 "periods of {} samples); only {:.2f} averaged periods are present",
                                 e.file, e.omega, y.size(), e.total_samples(), e.transient_periods, e.periods,
                                 e.samples_per_period,
                                 std::max(0.0, (static_cast<double>(y.size()) -
                                                e.transient_periods * e.samples_per_period) /
                                                   e.samples_per_period)));
  std::vector<std::size_t> outliers;
  const auto period = PeriodicAverage(y, static_cast<std::size_t>(e.transient_periods) * e.samples_per_period,
                                      e.samples_per_period, e.periods, &outliers);
  FrequencyPoint pt;
  EstimateFrequencyPoint(options, plan.nonlinear.h, plan.amplitude, e.omega, e.sample_time(), period, &pt, summary);
  pt.outliers = outliers;
  if (!outliers.empty())
    summary->message += fmt::format("; warning: {}: sample{} {} left out of the periodic average as isolated "
                                    "outlier{} (more than {:g} robust standard deviations from the phase's median "
                                    "over the periods)",
                                    e.file, outliers.size() > 1 ? "s" : "", fmt::join(OneBased(outliers), ", "),
                                    outliers.size() > 1 ? "s" : "", kOutlierSigmas);
  return pt;
}

std::string PlanStage(const nlohmann::json& j, const std::string& source) {
  if (!j.is_object() || !j.contains("method") || j.at("method") != "brouri" || !j.contains("stage") ||
      !j.at("stage").is_string())
    throw InputError(fmt::format("{}: not a brouri plan (expected \"method\": \"brouri\" and a \"stage\"); write one "
                                 "with `hwbounds brouri plan steps|sines`",
                                 source));
  const auto stage = j.at("stage").get<std::string>();
  if (stage != "steps" && stage != "sines")
    throw InputError(fmt::format("{}: stage '{}' must be 'steps' or 'sines'", source, stage));
  return stage;
}

Recording CheckRecording(const CsvTable& t, double sample_time, const std::string& y_col) {
  Recording r;
  r.y = t.column(y_col);
  if (t.has("u")) r.u = t.column("u");
  if (t.has("t") && t.rows() >= 2) {
    const auto& tt = t.column("t");
    for (std::size_t i = 1; i < tt.size(); ++i)
      if (std::abs(tt[i] - tt[i - 1] - sample_time) > 1e-6 * sample_time + 1e-9)
        throw InputError(fmt::format("{}: row {}: time step {} differs from the planned sample time {}", t.source,
                                     i + 1, tt[i] - tt[i - 1], sample_time));
  }
  return r;
}

Recording ReadRecording(const std::string& path, double sample_time, const std::string& y_col) {
  return CheckRecording(read_recording(path, {y_col}, {"u", "t"}), sample_time, y_col);
}

nlohmann::json StepsResultJson(const NonlinearEstimate& estimate, const Summary& summary) {
  nlohmann::json result = estimate.to_json();
  result["stage"] = "steps";
  result["summary"] = summary.message;
  return result;
}

nlohmann::json SinesResultJson(const SinePlan& plan, const std::vector<FrequencyPoint>& points) {
  nlohmann::json result = {{"stage", "sines"}, {"points", nlohmann::json::array()}};
  for (const auto& p : points) result["points"].push_back(ToJson(p));
  result["nonlinear"] = plan.nonlinear.to_json();
  result["note"] = "normalised model (eq. 4): G(0) = 1, phi = -arg G";
  return result;
}

}  // namespace hw::brouri
