// `hwbounds diagnose`: locate, name and refit what a nominal model leaves out (see docs/diagnose.md).
#include <memory>

#include <fmt/format.h>

#include "cli/commands.hpp"
#include "core/csv_table.hpp"
#include "core/output_files.hpp"
#include "core/hw_model.hpp"
#include "diagnose/diagnose.hpp"

namespace hw::cli {
namespace {

diagnose::Recording LoadRecording(const std::string& path, const std::string& u_col, const std::string& y_col,
                                  const std::string& t_col) {
  const CsvTable tab = read_csv(path);
  diagnose::Recording r;
  r.name = path;
  r.u = tab.column(u_col);
  r.y = tab.column(y_col);
  if (tab.has(t_col)) {
    r.t = tab.column(t_col);
    for (std::size_t i = 1; i < r.t.size(); ++i)
      if (!(r.t[i] > r.t[i - 1]))
        throw InputError(fmt::format("{}: column '{}' must increase strictly (data row {}: {} after {})", path, t_col,
                                     i + 1, r.t[i], r.t[i - 1]));
  } else {
    r.t.resize(r.u.size());
    for (std::size_t i = 0; i < r.t.size(); ++i) r.t[i] = static_cast<double>(i);
  }
  if (r.u.size() < 60)
    throw InputError(fmt::format("{}: {} samples; the diagnosis needs at least 60", path, r.u.size()));
  return r;
}

}  // namespace

void AddDiagnoseCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "diagnose",
      "Find where a model's simulation differs from a recording, name the missing effect, refit, validate");
  struct Opts {
    std::string data, validate, model, fit, out, u_col = "u", y_col = "y", t_col = "t", effects;
    diagnose::DiagnoseOptions o;
  };
  auto o = std::make_shared<Opts>();
  cmd->add_option("--data", o->data, "identification recording (CSV with header)")->required();
  cmd->add_option("--validate", o->validate, "validation recording (CSV with header)")->required();
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
    if (!o->effects.empty()) {
      std::size_t pos = 0;
      while (pos <= o->effects.size()) {
        const auto comma = o->effects.find(',', pos);
        const std::string tok = o->effects.substr(pos, comma == std::string::npos ? std::string::npos : comma - pos);
        const auto at = tok.find('@');
        if (at == std::string::npos) throw InputError(fmt::format("--effects: '{}' must be EFFECT@LOCATION, e.g. backlash@input", tok));
        const auto e = diagnose::ParseEffect(tok.substr(0, at));
        const auto l = diagnose::ParseLocation(tok.substr(at + 1));
        bool known = false;
        for (const auto& c : diagnose::CandidateEffects()) known = known || (c.first == e && c.second == l);
        if (!known) throw InputError(fmt::format("--effects: '{}' is not a defined effect block (see docs/diagnose.md)", tok));
        o->o.candidates.emplace_back(e, l);
        if (comma == std::string::npos) break;
        pos = comma + 1;
      }
    }
    const auto ident = LoadRecording(o->data, o->u_col, o->y_col, o->t_col);
    const auto valid = LoadRecording(o->validate, o->u_col, o->y_col, o->t_col);
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
