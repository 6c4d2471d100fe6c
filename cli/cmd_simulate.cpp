// `hwbounds simulate`: run a model JSON on an input recording and write y = w + noise.
#include <cmath>
#include <random>

#include <fmt/format.h>

#include "cli/commands.hpp"
#include "core/cerone_example.hpp"
#include "core/csv_table.hpp"
#include "core/hw_model.hpp"
#include "core/output_files.hpp"
#include "core/recording.hpp"

namespace hw::cli {
namespace {

std::vector<double> SampleIndex(std::size_t n) {
  std::vector<double> t(n);
  for (std::size_t i = 0; i < n; ++i) t[i] = static_cast<double>(i);
  return t;
}

}  // namespace

void AddSimulateCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "simulate", "Simulate a model (JSON) on an input CSV, or a built-in example; writes t,u,w,y[,noise_bound] (t: the input's "
      "time column when it has one, else the sample index)");
  struct Opts {
    std::string model, input, out, u_col = "u", example;
    int samples = 1000;
    double snr_db = 31.0;
    double noise_std = 0.0, noise_bound = 0.0;
    unsigned seed = 1;
    bool allow_unstable = false;
  };
  auto o = std::make_shared<Opts>();
  auto* model = cmd->add_option("--model", o->model, "model JSON (see docs/input_output.md: Model JSON)");
  auto* input = cmd->add_option("--input", o->input, "recording with the input column (CSV, or FILE.mat:u=VAR[,t=VAR])");
  auto* example = cmd->add_option("--example", o->example,
                                  "built-in example instead of --model/--input: cerone2011 (paper 001, Section VI)")
                      ->check(CLI::IsMember({"cerone2011"}));
  auto* samples = cmd->add_option("--samples", o->samples, "samples of the built-in example")->check(CLI::Range(10, 10000000));
  auto* snr = cmd->add_option("--snr-db", o->snr_db, "SNR_w of the built-in example (bounded uniform noise)");
  auto* u_col = cmd->add_option("--u-col", o->u_col, "input column name");
  auto* noise_std = cmd->add_option("--noise-std", o->noise_std, "Gaussian output noise standard deviation")
                        ->check(CLI::NonNegativeNumber);
  auto* noise_bound = cmd->add_option("--noise-bound", o->noise_bound, "uniform output noise in [-b, b] (bounded-error setting)")
                          ->check(CLI::NonNegativeNumber);
  cmd->add_flag("--allow-unstable", o->allow_unstable,
                "simulate a model whose linear block is unstable (its output grows without bound)");
  cmd->add_option("--seed", o->seed, "random seed");
  cmd->add_option("--out", o->out, "output CSV")->required();
  // The example has its own input, model and noise; a model run has no example settings.
  for (auto* opt : {model, input, u_col, noise_std, noise_bound}) example->excludes(opt);
  for (auto* opt : {samples, snr}) opt->needs(example);
  cmd->callback([o] {
    CheckOutputFile(o->out, "--out");
    if (!o->example.empty()) {
      const auto ex = SimulateCeroneExample(o->seed, o->samples, o->snr_db);
      CsvTable out;
      out.add_column("t", SampleIndex(ex.u.size()));
      out.add_column("u", ex.u);
      out.add_column("w", ex.w);
      out.add_column("y", ex.y);
      out.add_column("noise_bound", std::vector<double>(ex.y.size(), ex.noise_bound));
      write_csv(o->out, out, 17);
      fmt::print("wrote {} samples of {} (seed {}, noise bound {:.6g}, realised SNR {:.2f} dB) to {}\n", ex.y.size(),
                 o->example, o->seed, ex.noise_bound, ex.snr_db, o->out);
      return;
    }
    if (o->model.empty() || o->input.empty())
      throw InputError("simulate needs --model and --input, or --example NAME");
    const HwModel model = HwModel::load(o->model);
    CheckStableOrAllowed(model, o->model, o->allow_unstable);
    // The input's time column, when it has one (t=VAR, or a CSV column t), becomes the output's t.
    const CsvTable in = read_recording(o->input, {o->u_col}, {"t"});
    const auto& u = in.column(o->u_col);
    const auto w = model.simulate(u);
    CheckFiniteOutput(w, o->model, [&](std::size_t t) {
      return t < in.lines.size() ? fmt::format("{}:{}", o->input, in.lines[t]) : fmt::format("{} sample {}", o->input, t + 1);
    });
    std::mt19937_64 rng(o->seed);
    std::normal_distribution<double> gauss(0.0, 1.0);
    std::uniform_real_distribution<double> unif(-1.0, 1.0);
    std::vector<double> y(w.size());
    for (std::size_t i = 0; i < w.size(); ++i) y[i] = w[i] + o->noise_std * gauss(rng) + o->noise_bound * unif(rng);
    const std::vector<double> t = in.has("t") ? in.column("t") : SampleIndex(w.size());
    CsvTable out;
    out.add_column("t", t);
    out.add_column("u", u);
    out.add_column("w", w);
    out.add_column("y", y);
    if (o->noise_bound > 0) out.add_column("noise_bound", std::vector<double>(w.size(), o->noise_bound));
    write_csv(o->out, out);
    fmt::print("wrote {} samples to {}\n", w.size(), o->out);
  });
}

}  // namespace hw::cli
