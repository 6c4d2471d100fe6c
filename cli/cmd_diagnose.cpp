// `hwbounds diagnose`: locate, name and refit what a nominal model leaves out (see docs/diagnose.md).
#include <memory>

#include <fmt/format.h>

#include "cli/commands.hpp"
#include "core/input_error.hpp"
#include "core/output_files.hpp"
#include "diagnose/diagnose.hpp"

namespace hw::cli {
namespace {

struct Opts {
  std::string data, validate, model, fit, out, effects, state_variable = "position";
  diagnose::ColumnNames ident_cols, valid_cols;
  bool no_pairs = false, no_initial_state = false, keep_operating_point = false, no_richer = false;
  diagnose::DiagnoseOptions o;
};

void Run(const Opts& p, bool t_named, bool valid_t_named) {
  CheckOutputDirectory(p.out, "--out");
  diagnose::DiagnoseOptions o = p.o;
  std::string err;
  if (!diagnose::ValidNominalChoice(!p.model.empty(), !p.fit.empty(), &err)) throw InputError(err);
  if (!p.effects.empty()) o.candidates = diagnose::ParseCandidates(p.effects);
  o.state_variable = diagnose::ParseStateVariable(p.state_variable);
  o.try_pairs = !p.no_pairs;
  o.remove_operating_point = !p.keep_operating_point;
  o.richer_nominal = !p.no_richer;
  o.refit.estimate_initial_state = !p.no_initial_state;
  o.nominal_fit.refit.estimate_initial_state = !p.no_initial_state;
  if (!o.IsValid(&err)) throw InputError("diagnose: " + err);
  diagnose::ColumnNames ic = p.ident_cols, vc = p.valid_cols;
  ic.t_required = t_named;
  vc.t_required = valid_t_named;
  // Every input is checked before any work: the model or fit spec, then the recordings.
  diagnose::AugmentedModel nominal;
  std::unique_ptr<diagnose::NominalSpec> spec;
  if (!p.model.empty()) {
    nominal = diagnose::AugmentedModel::Load(p.model);
    if (nominal.has_block())
      throw InputError(fmt::format("{}: the model holds effect blocks ({}); give the nominal model without them",
                                   p.model, nominal.Label()));
  } else {
    spec = std::make_unique<diagnose::NominalSpec>(diagnose::NominalSpec::Parse(p.fit));
  }
  const auto ident = diagnose::ReadRecording(diagnose::RecordingSource::Parse(p.data, ic));
  const auto valid = diagnose::ReadRecording(diagnose::RecordingSource::Parse(p.validate, vc));
  if (spec) {
    const diagnose::NominalFit fit = diagnose::FitNominalForDiagnosis(*spec, ident, o);
    fmt::print("{}\n", fit.Summary());
    nominal = fit.model;
  }
  diagnose::DiagnoseReport report;
  diagnose::Diagnose(o, nominal, spec.get(), ident, valid, &report);
  if (!report.ok) throw InputError("diagnose: " + report.message);
  const auto files = diagnose::WriteReport(report, ident, valid, p.out);
  fmt::print("{}\n", report.message);
  if (!report.findings.empty()) {
    fmt::print("ranked candidates (score; held-out z, validation z):");
    for (std::size_t i = 0; i < report.findings.size() && i < 5; ++i) {
      const auto& f = report.findings[i];
      fmt::print(" {} {:.3f} ({:.1f}, {:.1f}){}", f.Label(), f.score, f.holdout.z, f.validation.z,
                 i + 1 < std::min<std::size_t>(5, report.findings.size()) ? "," : "\n");
    }
  }
  fmt::print("baseline: {}; {}\n", report.baseline_source, report.initial_state_note);
  fmt::print("wrote {} files to {} ({:.2f} s)\n", files.size(), p.out, report.seconds);
}

}  // namespace

void AddDiagnoseCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "diagnose",
      "Find where a model's simulation differs from a recording, name the missing effect, refit, validate");
  auto p = std::make_shared<Opts>();
  cmd->add_option("--data", p->data, "identification recording: FILE or FILE:u=NAME,y=NAME[,t=NAME]")->required();
  cmd->add_option("--validate", p->validate, "validation recording: FILE or FILE:u=NAME,y=NAME[,t=NAME]")->required();
  auto* m = cmd->add_option("--model", p->model, "nominal model JSON (docs/input_output.md: Model JSON)");
  auto* f = cmd->add_option("--fit", p->fit, "fit the nominal model first: linear:NA,NB[,DELAY] or hw:NA,NB,PIN,POUT[,DELAY]");
  m->excludes(f);
  cmd->add_option("--out", p->out, "output directory (report.json, report.md, figures)")->required();
  auto* tc = cmd->add_option("--t-col", p->ident_cols.t, "time column (sample index when absent)");
  cmd->add_option("--u-col", p->ident_cols.u, "input column (both recordings unless --validate-u-col)");
  cmd->add_option("--y-col", p->ident_cols.y, "output column (both recordings unless --validate-y-col)");
  auto* vu = cmd->add_option("--validate-u-col", p->valid_cols.u, "input column of the validation recording");
  auto* vy = cmd->add_option("--validate-y-col", p->valid_cols.y, "output column of the validation recording");
  auto* vt = cmd->add_option("--validate-t-col", p->valid_cols.t, "time column of the validation recording");
  cmd->add_option("--noise-std", p->o.noise_std, "output noise standard deviation")->default_str("estimated");
  cmd->add_option("--init-samples", p->o.init_samples, "leading samples excluded from costs (warm-up)");
  cmd->add_flag("--no-initial-state", p->no_initial_state,
                "simulate from rest instead of estimating the initial state of each recording");
  cmd->add_option("--holdout", p->o.holdout_fraction, "fraction of the identification recording held out for ranking");
  cmd->add_option("--min-improvement", p->o.min_improvement, "minimum penalised MSE reduction for a verdict");
  cmd->add_option("--significance-z", p->o.significance_z, "held-out paired z required");
  cmd->add_option("--validation-z", p->o.validation_z, "validation paired z required for a verdict");
  cmd->add_option("--window", p->o.windows.length, "window length of the residual test in samples (0 = auto)")->default_str("auto");
  cmd->add_option("--window-alpha", p->o.windows.alpha, "family-wise false-alarm probability of the residual windows");
  cmd->add_option("--effects", p->effects, "comma-separated candidates EFFECT@LOCATION")->default_str("all");
  cmd->add_option("--state-variable", p->state_variable,
                  "what the linear block's output is: position or velocity (force -> velocity drives)");
  cmd->add_flag("--no-pairs", p->no_pairs, "do not try combinations of two blocks");
  cmd->add_flag("--keep-operating-point", p->keep_operating_point,
                "diagnose u and y as recorded even when they lie far from 0 (default: in deviations from their medians)");
  cmd->add_flag("--no-richer-nominal", p->no_richer,
                "do not require an effect to beat a richer nominal structure (orders + 1, map degrees + 2)");
  cmd->add_option("--threads", p->o.threads, "parallel candidate fits (0 = all cores)");
  cmd->callback([p, cmd, tc, vu, vy, vt] {
    // Validation columns default to the identification ones unless named.
    if (!vu->count()) p->valid_cols.u = p->ident_cols.u;
    if (!vy->count()) p->valid_cols.y = p->ident_cols.y;
    if (!vt->count()) p->valid_cols.t = p->ident_cols.t;
    (void)cmd;
    Run(*p, tc->count() > 0, vt->count() > 0 || tc->count() > 0);
  });
}

}  // namespace hw::cli
