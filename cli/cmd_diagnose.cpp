// `hwbounds diagnose`: locate, name and refit what a nominal model leaves out (see docs/diagnose.md).
#include <memory>

#include <fmt/format.h>

#include "cli/commands.hpp"
#include "core/csv_table.hpp"
#include "core/output_files.hpp"
#include "core/hw_model.hpp"
#include "diagnose/diagnose.hpp"

namespace hw::cli {

void AddDiagnoseCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "diagnose",
      "Find where a model's simulation differs from a recording, name the missing effect, refit, validate");
  struct Opts {
    std::string data, validate, model, fit, out, u_col = "u", y_col = "y", t_col = "t", effects;
    diagnose::DiagnoseOptions o;
  };
  auto o = std::make_shared<Opts>();
  cmd->add_option("--data", o->data, "identification recording (CSV with header, or FILE.mat:u=VAR,y=VAR[,t=VAR])")
      ->required();
  cmd->add_option("--validate", o->validate, "validation recording (CSV or .mat, as --data)")->required();
  auto* m = cmd->add_option("--model", o->model, "nominal model JSON (README: Model JSON)");
  auto* f = cmd->add_option("--fit", o->fit, "fit the nominal model first: linear:NA,NB[,DELAY] or hw:NA,NB,PIN,POUT[,DELAY]");
  m->excludes(f);
  cmd->add_option("--out", o->out, "output directory (report.json, report.md, figures)")->required();
  cmd->add_option("--u-col", o->u_col, "input column");
  cmd->add_option("--y-col", o->y_col, "output column");
  cmd->add_option("--t-col", o->t_col, "time column (sample index when absent)");
  cmd->add_option("--noise-std", o->o.noise_std, "output noise standard deviation")->default_str("estimated");
  cmd->add_option("--init-samples", o->o.init_samples, "leading samples excluded from costs (transient from rest)");
  cmd->add_option("--holdout", o->o.holdout_fraction, "fraction of the identification recording held out for ranking");
  cmd->add_option("--min-improvement", o->o.min_improvement, "minimum penalised MSE reduction for a verdict");
  cmd->add_option("--significance-z", o->o.significance_z, "held-out paired z pre-screen");
  cmd->add_option("--validation-z", o->o.validation_z, "validation paired z required for a verdict");
  cmd->add_option("--window", o->o.windows.length, "mismatch window length in samples (0 = auto)")->default_str("auto");
  cmd->add_option("--effects", o->effects, "comma-separated candidates EFFECT@LOCATION")->default_str("all");
  cmd->callback([o] {
    CheckOutputDirectory(o->out, "--out");
    if (o->model.empty() == o->fit.empty()) throw InputError("diagnose needs exactly one of --model FILE or --fit SPEC");
    std::string err;
    if (!o->o.IsValid(&err)) throw InputError("diagnose: " + err);
    if (!o->effects.empty()) o->o.candidates = diagnose::ParseCandidates(o->effects);
    const auto ident = diagnose::LoadRecording(o->data, o->u_col, o->y_col, o->t_col);
    const auto valid = diagnose::LoadRecording(o->validate, o->u_col, o->y_col, o->t_col);
    HwModel nominal;
    if (!o->model.empty()) {
      nominal = HwModel::load(o->model);
    } else {
      const auto spec = diagnose::NominalSpec::Parse(o->fit);
      nominal = diagnose::FitNominal(spec, {&ident.u, &ident.y, o->o.init_samples});
    }
    diagnose::DiagnoseReport report;
    diagnose::Diagnose(o->o, nominal, ident, valid, &report);
    if (!report.ok) throw InputError("diagnose: " + report.message);
    const auto files = diagnose::WriteReport(report, ident, valid, o->out);
    fmt::print("{}\n", report.message);
    if (!report.findings.empty()) {
      fmt::print("ranked candidates (held-out score, z):");
      for (std::size_t i = 0; i < report.findings.size() && i < 4; ++i)
        fmt::print(" {}@{} {:.3f} ({:.1f}){}", diagnose::EffectName(report.findings[i].block.effect),
                   diagnose::LocationName(report.findings[i].block.location), report.findings[i].score,
                   report.findings[i].z, i + 1 < std::min<std::size_t>(4, report.findings.size()) ? "," : "");
      fmt::print("\n");
    }
    fmt::print("wrote {} files to {} ({:.2f} s)\n", files.size(), o->out, report.seconds);
  });
}

}  // namespace hw::cli
