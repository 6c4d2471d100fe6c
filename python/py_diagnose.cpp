// hwbounds.diagnose and hwbounds.scenario: discrepancy diagnosis (docs/diagnose.md), as the CLI runs it.
#include <fmt/format.h>

#include "core/hw_model.hpp"
#include "diagnose/diagnose.hpp"
#include "diagnose/scenario.hpp"
#include "python/py_convert.hpp"
#include "python/py_module.hpp"

namespace hw::python {
namespace {

// A recording: a spec string is read as `hwbounds diagnose --data SPEC` reads it (diagnose/recording.hpp);
// arrays are checked as the CLI checks a file's columns.
diagnose::Recording RecordingArg(py::handle h, const std::string& what) {
  if (py::isinstance<py::str>(h))
    return diagnose::ReadRecording(diagnose::RecordingSource::Parse(h.cast<std::string>(), diagnose::ColumnNames{}));
  const CsvTable t = RecordingFromPython(h, what, {"u", "y"}, {"t"});
  return diagnose::MakeRecording(what, t.has("t") ? t.column("t") : std::vector<double>{}, t.column("u"),
                                 t.column("y"));
}

py::dict RecordingDict(const diagnose::Recording& r) {
  py::dict d;
  d["t"] = ToArray(r.t);
  d["u"] = ToArray(r.u);
  d["y"] = ToArray(r.y);
  return d;
}

py::object Diagnose(py::handle ident_arg, py::handle valid_arg, py::handle model, py::handle fit, py::handle effects,
                    diagnose::DiagnoseOptions o, py::handle out_dir) {
  Require([&](std::string* e) { return diagnose::ValidNominalChoice(!model.is_none(), !fit.is_none(), e); });
  if (!effects.is_none())
    o.candidates = diagnose::ParseCandidates(py::isinstance<py::str>(effects)
                                                 ? effects.cast<std::string>()
                                                 : py::str(",").attr("join")(effects).cast<std::string>());
  RequireValid(o, "diagnose: ");
  const auto ident = RecordingArg(ident_arg, "ident");
  const auto valid = RecordingArg(valid_arg, "valid");
  diagnose::DiagnoseReport report;
  if (!model.is_none()) {
    const diagnose::AugmentedModel nominal = py::isinstance<py::str>(model)
                                                 ? diagnose::AugmentedModel::Load(model.cast<std::string>())
                                                 : diagnose::AugmentedModel::from_json(ToJson(model));
    if (nominal.has_block())
      throw InputError(fmt::format("diagnose: the model holds effect blocks ({}); give the nominal model without them",
                                   nominal.Label()));
    WithoutGil([&] {
      diagnose::Diagnose(o, nominal, nullptr, ident, valid, &report);
      return 0;
    });
  } else {
    const auto spec = diagnose::NominalSpec::Parse(fit.cast<std::string>());
    WithoutGil([&] {
      const diagnose::NominalFit nominal = diagnose::FitNominalForDiagnosis(spec, ident, o);
      diagnose::Diagnose(o, nominal.model, &spec, ident, valid, &report);
      return 0;
    });
  }
  if (!report.ok) throw InputError("diagnose: " + report.message);
  nlohmann::json j = diagnose::ReportJson(report, ident, valid);
  if (!out_dir.is_none()) j["files"] = diagnose::WriteReport(report, ident, valid, out_dir.cast<std::string>());
  return ToPython(j);
}

}  // namespace

void DefineDiagnose(py::module_& m) {
  const diagnose::DiagnoseOptions d;
  m.def(
      "diagnose",
      [](py::handle ident, py::handle valid, py::handle model, py::handle fit, py::handle effects, double noise_std,
         std::size_t init_samples, double holdout_fraction, double significance_z, double min_improvement,
         double validation_z, bool try_pairs, int pair_partners, int max_lag, int threads,
         const std::string& state_variable, int window_length, double window_alpha, bool refit_maps,
         bool fit_output_offset, bool estimate_initial_state, int keep_grid_points, bool remove_operating_point,
         bool richer_nominal, py::handle out_dir) {
        diagnose::DiagnoseOptions o;
        o.noise_std = noise_std;
        o.init_samples = init_samples;
        o.holdout_fraction = holdout_fraction;
        o.significance_z = significance_z;
        o.min_improvement = min_improvement;
        o.validation_z = validation_z;
        o.try_pairs = try_pairs;
        o.pair_partners = pair_partners;
        o.max_lag = max_lag;
        o.threads = threads;
        o.state_variable = diagnose::ParseStateVariable(state_variable);
        o.windows.length = window_length;
        o.windows.alpha = window_alpha;
        o.refit.refit_maps = refit_maps;
        o.refit.fit_output_offset = fit_output_offset;
        o.refit.estimate_initial_state = estimate_initial_state;
        o.nominal_fit.refit.estimate_initial_state = estimate_initial_state;
        o.refit.keep_grid_points = keep_grid_points;
        o.remove_operating_point = remove_operating_point;
        o.richer_nominal = richer_nominal;
        return Diagnose(ident, valid, model, fit, effects, o, out_dir);
      },
      R"doc(Discrepancy diagnosis (docs/diagnose.md), as `hwbounds diagnose`: where the nominal model's
simulation differs from the identification recording, which effect it leaves out, and whether inserting it
improves the validation recording. ident, valid: recordings (spec strings such as "rec.mat:u=vir,y=qm,t=time",
{"u": array, "y": array[, "t": array]} or (u, y)). Exactly one of model (Model JSON dict or file) and fit
("linear:NA,NB[,DELAY]" or "hw:NA,NB,PIN,POUT[,DELAY]"). effects: "backlash@input,..." or a list of such.
Options mirror diagnose::DiagnoseOptions (window_* = windows, refit_maps etc. = refit; estimate_initial_state
also applies to the nominal fit). out_dir: also write
the CLI's report files there. Returns report.json as a dict.)doc",
      py::arg("ident"), py::arg("valid"), py::arg("model") = py::none(), py::arg("fit") = py::none(), py::kw_only(),
      py::arg("effects") = py::none(), py::arg("noise_std") = d.noise_std, py::arg("init_samples") = d.init_samples,
      py::arg("holdout_fraction") = d.holdout_fraction, py::arg("significance_z") = d.significance_z,
      py::arg("min_improvement") = d.min_improvement, py::arg("validation_z") = d.validation_z,
      py::arg("try_pairs") = d.try_pairs, py::arg("pair_partners") = d.pair_partners, py::arg("max_lag") = d.max_lag,
      py::arg("threads") = d.threads, py::arg("state_variable") = "position",
      py::arg("window_length") = d.windows.length, py::arg("window_alpha") = d.windows.alpha,
      py::arg("refit_maps") = d.refit.refit_maps, py::arg("fit_output_offset") = d.refit.fit_output_offset,
      py::arg("estimate_initial_state") = d.refit.estimate_initial_state,
      py::arg("keep_grid_points") = d.refit.keep_grid_points, py::arg("remove_operating_point") = d.remove_operating_point,
      py::arg("richer_nominal") = d.richer_nominal, py::arg("out_dir") = py::none());

  const diagnose::ScenarioOptions s;
  m.def(
      "scenario",
      [](const std::string& hidden_effect, py::handle location, double effect_rms_ratio, double effect_fraction,
         std::size_t samples, unsigned seed) {
        diagnose::ScenarioOptions o;
        o.effect = diagnose::ParseEffect(hidden_effect);
        if (!location.is_none()) o.location = static_cast<int>(diagnose::ParseLocation(location.cast<std::string>()));
        o.effect_rms_ratio = effect_rms_ratio;
        o.effect_fraction = effect_fraction;
        o.samples = samples;
        o.seed = seed;
        const auto sc = diagnose::MakeScenario(o);
        py::dict out;
        out["ident"] = RecordingDict(sc.ident);
        out["valid"] = RecordingDict(sc.valid);
        out["truth"] = ToPython(sc.truth_json());
        out["ident_effect_contribution"] = ToArray(sc.ident_contribution);
        out["noise_std"] = sc.noise_std;
        out["effect_rms"] = sc.effect_rms;
        return out;
      },
      R"doc(A recording pair of a system with one concealed effect (or "none"), as `hwbounds scenario`:
{"ident": {t, u, y}, "valid": {t, u, y}, "truth": ..., "ident_effect_contribution", "noise_std", "effect_rms"}.
Options mirror diagnose::ScenarioOptions; location None = the effect's usual location.)doc",
      py::arg("hidden_effect") = "none", py::arg("location") = py::none(), py::kw_only(),
      py::arg("effect_rms_ratio") = s.effect_rms_ratio, py::arg("effect_fraction") = s.effect_fraction,
      py::arg("samples") = s.samples, py::arg("seed") = s.seed);
}

}  // namespace hw::python
