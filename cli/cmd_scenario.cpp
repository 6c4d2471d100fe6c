// `hwbounds scenario`: a recording pair with one concealed effect (or none), for testing `diagnose`.
#include <memory>

#include <fmt/format.h>

#include "cli/commands.hpp"
#include "core/csv_table.hpp"
#include "core/output_files.hpp"
#include "diagnose/scenario.hpp"

namespace hw::cli {

void AddScenarioCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "scenario", "Generate identification and validation recordings of a system with a concealed effect "
                  "(writes OUT_ident.csv, OUT_valid.csv, OUT_truth.json)");
  struct Opts {
    std::string effect = "none", location, out;
    diagnose::ScenarioOptions s;
  };
  auto o = std::make_shared<Opts>();
  cmd->add_option("--hidden-effect", o->effect, "effect name (docs/diagnose.md) or none")->required();
  cmd->add_option("--location", o->location, "input, output or state")->default_str("the effect's usual location");
  cmd->add_option("--effect-rms-ratio", o->s.effect_rms_ratio, "effect RMS / noise standard deviation");
  cmd->add_option("--effect-fraction", o->s.effect_fraction, "effect RMS / std of the linear output (0 = random 4-8 %)")
      ->default_str("random 4-8 %");
  cmd->add_option("--samples", o->s.samples, "samples per recording");
  cmd->add_option("--seed", o->s.seed, "random seed");
  cmd->add_option("--out", o->out, "output prefix, e.g. runs/backlash1")->required();
  cmd->callback([o] {
    const std::string ident = o->out + "_ident.csv", valid = o->out + "_valid.csv", truth = o->out + "_truth.json";
    for (const auto& path : {ident, valid, truth}) CheckOutputFile(path, "--out");
    o->s.effect = diagnose::ParseEffect(o->effect);
    if (!o->location.empty()) o->s.location = static_cast<int>(diagnose::ParseLocation(o->location));
    const auto sc = diagnose::MakeScenario(o->s);
    OutputFiles files;
    auto write = [&](const diagnose::Recording& r, const std::string& path, bool with_truth) {
      CsvTable t;
      t.add_column("t", r.t);
      t.add_column("u", r.u);
      t.add_column("y", r.y);
      if (with_truth) {
        t.add_column("effect_contribution", sc.ident_contribution);
        std::vector<double> a(sc.ident_active.begin(), sc.ident_active.end());
        t.add_column("effect_active", a);
      }
      files.Add(path, format_csv(t, 17));
    };
    write(sc.ident, ident, true);
    write(sc.valid, valid, false);
    files.Add(truth, sc.truth_json().dump(2) + "\n");
    files.Commit();
    fmt::print("wrote {0}_ident.csv, {0}_valid.csv, {0}_truth.json: {1}, effect RMS {2:.4g}, noise std {3:.4g}\n", o->out,
               o->effect, sc.effect_rms, sc.noise_std);
  });
}

}  // namespace hw::cli
