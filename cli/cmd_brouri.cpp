// `hwbounds brouri`: Brouri's two-stage frequency identification of HW systems with backlash input.
//   brouri plan steps  -> plan.json + steps.csv (t,u): the piecewise-constant input of stage 1
//   brouri plan sines  -> plan.json + sine_<i>.csv (t,z,u): pre-compensated sines of stage 2
//   brouri estimate    -> reads the recordings (the planned CSVs with a y column added), prints and writes JSON
//   brouri simulate    -> records a plan on a simulated system (default: the paper's Section 6 system)
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "cli/commands.hpp"
#include "core/atomic_write.hpp"
#include "core/csv_table.hpp"
#include "core/json_input.hpp"
#include "core/output_files.hpp"
#include "estimators/brouri/experiment.hpp"

namespace hw::cli {
namespace {
namespace fs = std::filesystem;
using namespace hw::brouri;

nlohmann::json ReadJson(const std::string& path) { return ReadJsonFile(path, "JSON file"); }

// Runs a reader of JSON contents, prefixing its errors with the file they came from.
template <class Read>
auto FromFile(const std::string& path, Read&& read) {
  try {
    return read();
  } catch (const InputError& e) {
    throw InputError(fmt::format("{}: {}", path, e.what()));
  }
}

// The stage-1 estimate from a `brouri estimate` result: the stage-1 file itself, or a stage-2 file's copy.
NonlinearEstimate ReadNonlinearEstimate(const std::string& path) {
  const auto j = ReadJson(path);
  return FromFile(path, [&] {
    if (j.is_object() && j.contains("nonlinear")) {
      CheckKeys(j, {"stage", "points", "nonlinear", "note"}, "stage-2 result");
      return NonlinearEstimate::from_json(j.at("nonlinear"));
    }
    return NonlinearEstimate::from_json(j, {"stage", "summary"});
  });
}

std::vector<double> Times(std::size_t n, double ts) {
  std::vector<double> t(n);
  for (std::size_t i = 0; i < n; ++i) t[i] = i * ts;
  return t;
}

void AddBrouriPlan(CLI::App& brouri) {
  auto* plan = brouri.add_subcommand("plan", "Write the inputs a user must apply (stage 1: steps, stage 2: sines)");
  plan->require_subcommand(1);

  struct StepOpts {
    std::vector<double> up, down;
    double reset = NAN, ts = 0.5, settling = 80.0;
    int m = 100;
    std::string out_dir;
  };
  auto so = std::make_shared<StepOpts>();
  auto* steps = plan->add_subcommand("steps", "Stage 1: reset hold, ascending holds, descending holds");
  steps->add_option("--levels-up", so->up, "ascending levels U_1 < ... < U_N (comma list)")->required()->delimiter(',');
  steps->add_option("--levels-down", so->down, "descending levels (comma list, decreasing)")->required()->delimiter(',');
  steps->add_option("--reset", so->reset, "reset level applied first (below U_1)")
      ->default_str("the lowest descending level");
  steps->add_option("--sample-time", so->ts, "sample time Ts (s)")->check(CLI::PositiveNumber);
  steps->add_option("--settling-time", so->settling, "upper bound on the settling time of G (s): each hold waits this long")
      ->check(CLI::PositiveNumber);
  steps->add_option("--average-samples", so->m, "M: samples averaged at the end of each hold (eq. 9)")
      ->check(CLI::Range(2, 100000000));
  steps->add_option("--out-dir", so->out_dir, "directory for plan.json and steps.csv")->required();
  steps->callback([so] {
    CheckOutputDirectory(so->out_dir, "--out-dir");
    double reset = so->reset;
    if (std::isnan(reset)) {
      if (so->down.empty()) throw InputError("--levels-down is empty");
      reset = std::min(*std::min_element(so->down.begin(), so->down.end()),
                       so->up.empty() ? 0.0 : so->up.front() - 1.0);
    }
    const StepPlan p = MakeStepPlan(so->up, so->down, reset, so->ts, so->settling, so->m);
    const auto u = p.Input();
    CsvTable t;
    t.add_column("t", Times(u.size(), p.sample_time));
    t.add_column("u", u);
    OutputFiles files;
    files.Add(so->out_dir + "/" + p.file, format_csv(t, 15));
    files.Add(so->out_dir + "/plan.json", p.to_json().dump(2) + "\n");
    fs::create_directories(so->out_dir);
    files.Commit();
    fmt::print("stage-1 plan: {} holds of {} samples ({} s each, last M = {} averaged), {} samples = {:.6g} s in all\n",
               p.Levels().size(), p.hold_samples, p.hold_samples * p.sample_time, p.average_samples, u.size(),
               u.size() * p.sample_time);
    fmt::print("apply column u of {0}/{1} (held between samples), add the measured output as column y, then run\n"
               "  hwbounds brouri estimate --plan {0}/plan.json --out nonlinear.json\n",
               so->out_dir, p.file);
  });

  struct SineOpts {
    std::string nonlinear, out_dir;
    std::vector<double> omegas;
    double amplitude = 1.0, settling = 80.0;
    int spp = 512, periods = 50;
  };
  auto si = std::make_shared<SineOpts>();
  auto* sines = plan->add_subcommand("sines", "Stage 2: sines through the backlash pre-compensator built from stage 1");
  sines->add_option("--nonlinear", si->nonlinear, "stage-1 result JSON (from `brouri estimate`)")->required();
  sines->add_option("--omegas", si->omegas, "frequencies in rad/s (comma list)")->required()->delimiter(',');
  sines->add_option("--amplitude", si->amplitude, "sine amplitude U of z = U sin(omega t)")->check(CLI::PositiveNumber);
  sines->add_option("--samples-per-period", si->spp, "samples per period (sample time = 2 pi / omega / this)")
      ->check(CLI::Range(4, 1000000));
  sines->add_option("--periods", si->periods, "N: periods averaged (eq. 23)")->check(CLI::Range(1, 1000000));
  sines->add_option("--settling-time", si->settling, "settling time of G (s): whole periods discarded first")
      ->check(CLI::NonNegativeNumber);
  sines->add_option("--out-dir", si->out_dir, "directory for plan.json and sine_<i>.csv")->required();
  sines->callback([si] {
    CheckOutputDirectory(si->out_dir, "--out-dir");
    const NonlinearEstimate est = ReadNonlinearEstimate(si->nonlinear);
    std::vector<double> omegas = si->omegas;
    std::sort(omegas.begin(), omegas.end());
    const SinePlan p = MakeSinePlan(est, omegas, si->amplitude, si->spp, si->periods, si->settling);
    OutputFiles files;
    for (std::size_t i = 0; i < p.experiments.size(); ++i) {
      const auto& e = p.experiments[i];
      CsvTable t;
      const auto z = p.Command(i);
      t.add_column("t", Times(z.size(), e.sample_time()));
      t.add_column("z", z);
      t.add_column("u", p.Input(i));
      files.Add(si->out_dir + "/" + e.file, format_csv(t, 15));
      fmt::print("  {}: omega = {} rad/s, Ts = {:.6g} s, {} transient + {} averaged periods = {:.6g} s\n", e.file,
                 e.omega, e.sample_time(), e.transient_periods, e.periods, e.total_samples() * e.sample_time());
    }
    files.Add(si->out_dir + "/plan.json", p.to_json().dump(2) + "\n");
    fs::create_directories(si->out_dir);
    files.Commit();
    fmt::print("stage-2 plan ({} pre-compensator for the estimated {}): apply column u of each file, add column y,\n"
               "then run  hwbounds brouri estimate --plan {}/plan.json --out frequency.json\n",
               ToString(est.kind == OperatorKind::kBacklash ? OperatorKind::kBacklashInverse : OperatorKind::kBacklash),
               ToString(est.kind), si->out_dir);
  });
}

struct EstimateOpts {
  std::string plan, data, out, y_col = "y", down_border = "leading-and-root";
  int degree = 0, max_degree = 9, harmonic = 0;
  double plateau_sigmas = 5.0;
  bool no_zoh = false, joint_refit = false;
};

NonlinearOptions NonlinearOptionsOf(const EstimateOpts& o) {
  NonlinearOptions opt;
  opt.degree = o.degree;
  opt.max_degree = o.max_degree;
  opt.plateau_sigmas = o.plateau_sigmas;
  opt.down_border = DownBorderMethodFromString(o.down_border);
  opt.joint_refit = o.joint_refit;
  return opt;
}

FrequencyOptions FrequencyOptionsOf(const EstimateOpts& o) {
  FrequencyOptions opt;
  opt.harmonic = o.harmonic;
  opt.zoh_correction = !o.no_zoh;
  return opt;
}

void AddBrouriEstimate(CLI::App& brouri) {
  auto o = std::make_shared<EstimateOpts>();
  auto* cmd = brouri.add_subcommand("estimate", "Estimate from recordings of a plan (stage 1 or 2, read from the plan)");
  cmd->add_option("--plan", o->plan, "plan.json written by `brouri plan`")->required();
  cmd->add_option("--data", o->data, "directory of the recordings")->default_str("the plan's directory");
  cmd->add_option("--y-col", o->y_col, "name of the measured-output column");
  // --degree, --max-degree, --plateau-sigmas, --harmonic: checked by NonlinearOptions/FrequencyOptions::IsValid
  // before the recordings are read (the Python module's messages).
  cmd->add_option("--degree", o->degree, "stage 1: degree p of h, 1..15 (0 = select from the data)");
  cmd->add_option("--max-degree", o->max_degree, "stage 1: largest degree the selection tries, 1..15");
  cmd->add_option("--plateau-sigmas", o->plateau_sigmas, "stage 1: plateau test threshold in standard errors");
  cmd->add_option("--down-border", o->down_border,
                  "stage 1: S^d, d- reading: leading-and-root | paper-coefficients | root-and-slope");
  cmd->add_flag("--joint-refit", o->joint_refit,
                "stage 1: refit h, d+, S^d, d- to both borders' points jointly (not in the paper; needs p + 4 points)");
  cmd->add_option("--harmonic", o->harmonic, "stage 2: harmonic k used for |G|, 1..15 (0 = degree of h, eq. 37)");
  cmd->add_flag("--no-zoh-correction", o->no_zoh, "stage 2: do not correct for the hold (sinc gain, Ts/2 delay)");
  cmd->add_option("--out", o->out, "result JSON")->required();
  cmd->callback([o] {
    CheckOutputFile(o->out, "--out");
    const NonlinearOptions nonlinear = NonlinearOptionsOf(*o);
    const FrequencyOptions frequency = FrequencyOptionsOf(*o);
    std::string error;
    if (!nonlinear.IsValid(&error) || !frequency.IsValid(&error)) throw InputError(error);
    const auto j = ReadJson(o->plan);
    const auto stage = PlanStage(j, o->plan);
    const std::string dir = o->data.empty() ? fs::path(o->plan).parent_path().string() : o->data;
    auto path_of = [&](const std::string& file) { return (fs::path(dir.empty() ? "." : dir) / file).string(); };
    nlohmann::json result;
    if (stage == "steps") {
      const StepPlan plan = FromFile(o->plan, [&] { return StepPlan::from_json(j); });
      const NonlinearOptions& opt = nonlinear;
      const auto rec = ReadRecording(path_of(plan.file), plan.sample_time, o->y_col);
      Summary s;
      const auto est = EstimateFromSteps(plan, opt, rec.u, rec.y, &s);
      fmt::print("{}\n", s.message);
      fmt::print("{:>4} {:>10} {:>12} {:>10}  {}\n", "j", "U_j", "X^_j(M)", "std err", "role");
      auto line = [&](int j, const HoldAverage& h, const char* role) {
        fmt::print("{:>4} {:>10.5g} {:>12.6f} {:>10.2g}  {}\n", j, h.level, h.mean, h.std_error, role);
      };
      line(0, est.reset, "reset");
      for (std::size_t i = 0; i < est.up.size(); ++i)
        line(static_cast<int>(i + 1), est.up[i], static_cast<int>(i) < est.j_a ? "plateau" : "ascending border");
      for (std::size_t i = 0; i < est.down.size(); ++i)
        line(static_cast<int>(est.up.size() + i + 1), est.down[i],
             static_cast<int>(i) < est.j_d ? "plateau" : "descending border");
      std::string hs;
      for (std::size_t i = est.h.size(); i-- > 1;) hs += fmt::format("{:+.6g} w^{} ", est.h[i], i);
      fmt::print("h^(w) = {}\n", hs);
      result = StepsResultJson(est, s);
    } else {
      const SinePlan plan = FromFile(o->plan, [&] { return SinePlan::from_json(j); });
      const FrequencyOptions& opt = frequency;
      std::vector<FrequencyPoint> points;
      for (std::size_t i = 0; i < plan.experiments.size(); ++i) {
        const auto& e = plan.experiments[i];
        const auto rec = ReadRecording(path_of(e.file), e.sample_time(), o->y_col);
        Summary s;
        points.push_back(EstimateFromSine(plan, i, opt, rec.u, rec.y, &s));
        if (!points.back().outliers.empty()) fmt::print("{}\n", s.message);
      }
      UnwrapPhases(&points);
      fmt::print("{:>10} {:>10} {:>12} {:>9} {:>9}\n", "omega", "|G^|", "phi^ (rad)", "harmonic", "misfit");
      for (const auto& p : points)
        fmt::print("{:>10.5g} {:>10.5f} {:>12.5f} {:>9} {:>9.2g}\n", p.omega, p.gain, p.phase, p.harmonic,
                   p.fit_residual);
      result = SinesResultJson(plan, points);
    }
    write_text_atomic(o->out, result.dump(2) + "\n");
    fmt::print("wrote {}\n", o->out);
  });
}

void AddBrouriSimulate(CLI::App& brouri) {
  struct Opts {
    std::string plan, out_dir, system;
    std::uint64_t seed = 1;
    double noise_std = NAN;
  };
  auto o = std::make_shared<Opts>();
  auto* cmd = brouri.add_subcommand("simulate", "Record a plan on a simulated system (adds column y to the plan's CSVs)");
  cmd->add_option("--plan", o->plan, "plan.json")->required();
  cmd->add_option("--system", o->system, "system JSON (see docs/brouri.md)")->default_str("the paper's Section 6 system");
  cmd->add_option("--noise-std", o->noise_std, "override the system's output noise standard deviation")
      ->default_str("the system's");
  cmd->add_option("--seed", o->seed, "noise seed");
  cmd->add_option("--out-dir", o->out_dir, "directory for the recordings")->default_str("the plan's directory");
  cmd->callback([o] {
    const auto j = ReadJson(o->plan);
    const auto stage = PlanStage(j, o->plan);
    BacklashHwSystem sys =
        o->system.empty() ? BacklashHwSystem::PaperExample()
                          : FromFile(o->system, [&] { return BacklashHwSystem::from_json(ReadJson(o->system)); });
    if (!std::isnan(o->noise_std)) sys.noise_std = o->noise_std;
    const std::string dir = o->out_dir.empty() ? fs::path(o->plan).parent_path().string() : o->out_dir;
    CheckOutputDirectory(dir.empty() ? "." : dir, "--out-dir");
    OutputFiles files;
    auto write = [&](const std::string& file, double ts, const std::vector<double>& u, const std::vector<double>* z,
                     std::uint64_t seed) {
      CsvTable t;
      t.add_column("t", Times(u.size(), ts));
      if (z) t.add_column("z", *z);
      t.add_column("u", u);
      t.add_column("y", Simulate(sys, u, ts, seed).y);
      files.Add((fs::path(dir.empty() ? "." : dir) / file).string(), format_csv(t, 15));
    };
    if (stage == "steps") {
      const StepPlan p = FromFile(o->plan, [&] { return StepPlan::from_json(j); });
      write(p.file, p.sample_time, p.Input(), nullptr, o->seed);
    } else {
      const SinePlan p = FromFile(o->plan, [&] { return SinePlan::from_json(j); });
      for (std::size_t i = 0; i < p.experiments.size(); ++i) {
        const auto z = p.Command(i);
        write(p.experiments[i].file, p.experiments[i].sample_time(), p.Input(i), &z, o->seed + 1000 + i);
      }
    }
    if (!dir.empty()) fs::create_directories(dir);
    files.Commit();
    for (const auto& [path, text] : files.files()) fmt::print("wrote {}\n", path);
  });
}

}  // namespace

void AddBrouriCommand(CLI::App& app) {
  auto* brouri = app.add_subcommand(
      "brouri", "Brouri's frequency identification of HW systems with backlash input (plan, estimate, simulate)");
  brouri->require_subcommand(1);
  AddBrouriPlan(*brouri);
  AddBrouriEstimate(*brouri);
  AddBrouriSimulate(*brouri);
}

}  // namespace hw::cli
