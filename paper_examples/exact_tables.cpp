// The exact set D against the paper's Table I on a committed realisation: the D^ss(2) intervals at δ = 3 of a
// committed `cerone_tables` run (paper_examples/results/*/tables.json) are the proven start box; the recording is
// regenerated from the run's seed, noise level and length (the same simulator); stage 2 bounds D inside the box.
// Writes OUT/exact_table.md and OUT/exact.json: exact outer, inner, D^ss(2) at δ = 3, the paper's interval and
// the ratios, with the stage-2 counts and time (the stage-1 time is the committed run's).
//
//   exact_tables --tables paper_examples/results/cerone_n23_snr31_delta3/tables.json --out DIR [--threads 2]
//   exact_tables --summarise DIR1 DIR2 ... --summary-out FILE.md   (one table over earlier runs)
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>

#include <CLI/CLI.hpp>
#include <fmt/format.h>
#include <fmt/ranges.h>
#include <nlohmann/json.hpp>

#include "core/atomic_write.hpp"
#include "core/cerone_example.hpp"
#include "core/csv_table.hpp"
#include "dss/hw_outer_set.hpp"
#include "exact/exact_bounds.hpp"
#include "exact/lp_solver.hpp"
#include "paper_examples/cerone/paper_table.hpp"

namespace {

using namespace hw;

struct StageOne {
  exact::ParamBox box;
  std::vector<std::pair<double, double>> intervals;
  double seconds = 0.0;
  uint64_t seed = 1;
  int samples = 1000;
  double snr_db = 31.0;
  int order = 0;  // δ of the run the box comes from
};

// The D^ss(2) run at the highest order of the committed case (n = 2); outer_runs is keyed by the order.
StageOne ReadStageOne(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw InputError(fmt::format("{}: cannot read", path));
  const nlohmann::json j = nlohmann::json::parse(in);
  for (const auto& c : j.at("cases")) {
    if (c.at("n").get<int>() != 2) continue;
    StageOne s;
    std::string key;
    for (const auto& [order, run] : c.at("outer_runs").items())
      if (key.empty() || std::stoi(order) > std::stoi(key)) key = order;
    const auto& run = c.at("outer_runs").at(key);
    s.order = std::stoi(key);
    for (const auto& iv : run.at("intervals")) {
      const double lo = iv.at("lower").at("value").get<double>(), hi = iv.at("upper").at("value").get<double>();
      s.box.emplace_back(lo, hi);
      s.intervals.emplace_back(lo, hi);
    }
    s.seconds = run.at("timing").value("wall_seconds", 0.0);
    s.seed = c.at("seed").get<uint64_t>();
    s.samples = c.at("samples").get<int>();
    s.snr_db = c.at("snr_db").get<double>();
    return s;
  }
  throw InputError(fmt::format("{}: no case with n = 2", path));
}

std::string Table(const exact::ExactBoundsSummary& s, const StageOne& one, const std::vector<double>& truth) {
  std::string md = fmt::format("| parameter | exact lower | exact upper | inner lower | inner upper | outer/inner | "
                               "D^ss(2) δ={} | paper Table I (n = 2) | exact/paper half-width | exact/D^ss half-width "
                               "| truth |\n",
                               one.order);
  md += "|---|---|---|---|---|---|---|---|---|---|---|\n";
  for (std::size_t k = 0; k < s.intervals.size(); ++k) {
    const auto& iv = s.intervals[k];
    const double w = iv.upper.value - iv.lower.value;
    const auto paper = cerone::PaperTableInterval(iv.name, 2);
    const std::string inner_lo = iv.inner ? fmt::format("{:.6g}", iv.inner->first) : "-";
    const std::string inner_hi = iv.inner ? fmt::format("{:.6g}", iv.inner->second) : "-";
    const std::string ratio = iv.inner && iv.inner->second > iv.inner->first
                                  ? fmt::format("{:.2f}", w / (iv.inner->second - iv.inner->first))
                                  : "-";
    md += fmt::format("| {} | {:.6g} | {:.6g} | {} | {} | {} | [{:.4g}, {:.4g}] | {} | {} | {:.3g} | {:.6g} {} |\n",
                      iv.name, iv.lower.value, iv.upper.value, inner_lo, inner_hi, ratio, one.intervals[k].first,
                      one.intervals[k].second,
                      paper ? fmt::format("[{:.3f}, {:.3f}]", paper->lower, paper->upper) : "-",
                      paper ? fmt::format("{:.3g}", w / (paper->upper - paper->lower)) : "-",
                      w / (one.intervals[k].second - one.intervals[k].first), truth[k],
                      iv.lower.value <= truth[k] && truth[k] <= iv.upper.value ? "inside" : "OUTSIDE");
  }
  return md;
}

// The order δ of the committed run whose n = 2 intervals are `start_box` (the box a run of this program started
// from), or 0 when none matches.
int OrderOfStartBox(const std::string& tables, const exact::ParamBox& start_box) {
  std::ifstream in(tables);
  if (!in) return 0;
  const nlohmann::json j = nlohmann::json::parse(in);
  for (const auto& c : j.at("cases")) {
    if (c.at("n").get<int>() != 2) continue;
    for (const auto& [order, run] : c.at("outer_runs").items()) {
      const auto& ivs = run.at("intervals");
      bool same = ivs.size() == start_box.size();
      for (std::size_t k = 0; same && k < ivs.size(); ++k)
        same = ivs[k].at("lower").at("value").get<double>() == start_box[k].lo &&
               ivs[k].at("upper").at("value").get<double>() == start_box[k].hi;
      if (same) return std::stoi(order);
    }
  }
  return 0;
}

// Where a run's start box came from: a committed D^ss(2) run of the same record, or of another record (a held-out
// seed or another length: an assumed prior box for this one).
std::string StartBoxLabel(int order, bool proven_for_this_record) {
  if (order == 0) return "no committed D^ss(2) run matches";
  return proven_for_this_record ? fmt::format("D^ss(2) at δ = {}", order)
                                : fmt::format("D^ss(2) at δ = {} of another record (an assumed prior box)", order);
}

// One table over several runs of this program (DIR/exact.json each; run from the repository root, where the
// runs' stage-1 paths are relative to): per parameter and realisation, outer/inner
// and the exact interval's width against the paper's Table I and against D^ss(2); then each run's counts.
std::string Summary(const std::vector<std::string>& dirs) {
  struct Run {
    std::string dir;
    nlohmann::json j;
    int order = 0;
  };
  std::vector<Run> runs;
  for (const auto& d : dirs) {
    std::ifstream in(d + "/exact.json");
    if (!in) throw InputError(fmt::format("{}/exact.json: cannot read", d));
    Run r{d, nlohmann::json::parse(in)};
    r.order = OrderOfStartBox(r.j.at("stage1").at("tables").get<std::string>(), exact::BoxFromJson(r.j.at("start_box")));
    runs.push_back(std::move(r));
  }
  auto realisation = [](const Run& r) {
    const auto& z = r.j.at("realisation");
    return fmt::format("seed {}, {:g} dB", z.at("seed").get<int>(), z.at("snr_db").get<double>());
  };
  std::string md = "Each cell: outer/inner · exact width / paper Table I width · exact width / D^ss(2) width.\n\n| parameter |";
  for (const auto& r : runs) md += fmt::format(" {} |", realisation(r));
  md += "\n|---|";
  for (std::size_t i = 0; i < runs.size(); ++i) md += "---|";
  md += "\n";
  const auto truth = CeroneExample::TrueParameters();
  const std::size_t n = runs.front().j.at("intervals").size();
  for (std::size_t k = 0; k < n; ++k) {
    const std::string name = runs.front().j.at("intervals")[k].at("name").get<std::string>();
    md += "| " + name + " |";
    for (const auto& r : runs) {
      const auto& iv = r.j.at("intervals")[k];
      const double lo = iv.at("lower").at("value").get<double>(), hi = iv.at("upper").at("value").get<double>();
      const auto& inner = iv.at("inner");
      const auto& box = r.j.at("start_box")[k];
      const auto paper = cerone::PaperTableInterval(name, 2);
      const bool inside = lo <= truth[k] && truth[k] <= hi;
      md += fmt::format(" {:.2f} · {} · {:.3g}{} |", (hi - lo) / (inner[1].get<double>() - inner[0].get<double>()),
                        paper ? fmt::format("{:.3g}", (hi - lo) / (paper->upper - paper->lower)) : "-",
                        (hi - lo) / (box[1].get<double>() - box[0].get<double>()), inside ? "" : " **truth outside**");
    }
    md += "\n";
  }
  for (const auto& r : runs)
    if (r.j.at("realisation").at("snr_db").get<double>() != 31.0) {
      md += "\nThe paper's Table I is at its stated 31 dB: at another SNR the middle ratio compares a record of other "
            "noise with it.\n";
      break;
    }
  md += "\n| run | start box | stage 2 wall | LPs (not optimal) | levels, boxes pruned | assumption |\n|---|---|---|---|---|---|\n";
  for (const auto& r : runs) {
    const auto& s2 = r.j.at("stage2");
    md += fmt::format("| [{}]({}/exact_table.md) | {} | {:.0f} s on {} | {} ({}) | {}, {} | {} |\n",
                      realisation(r), r.dir.substr(r.dir.find_last_of('/') + 1),
                      StartBoxLabel(r.order, r.j.at("stage1").value("start_box_proven_for_this_record", true)),
                      s2.at("wall_seconds").get<double>(), s2.at("executor").get<std::string>(), s2.at("lps").get<int>(),
                      s2.at("lp_failures").get<int>(), s2.at("prune_levels").get<int>(), s2.at("boxes_pruned").get<int>(),
                      r.j.at("assumption").at("holds").get<bool>() ? "holds" : "not shown");
  }
  return md;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Exact-set intervals against the paper's Table I on a committed realisation"};
  std::string tables, out;
  int threads = 2, lp_budget = exact::ObjectiveSearchOptions{}.lp_budget, sweeps = exact::ExactBoundsOptions{}.sweeps;
  std::string lp_solver = exact::ExactBoundsOptions{}.lp_solver;
  std::string split = exact::ToString(exact::ObjectiveSearchOptions{}.split);
  int samples = 0, seed = 0;
  std::string gamma_ratio = exact::ToString(exact::ObjectiveSearchOptions{}.gamma_ratio);
  std::string run_dir;
  std::vector<std::string> parameters;
  std::vector<std::string> summarise;
  std::string summary_out;
  app.add_option("--tables", tables, "a committed cerone_tables result (tables.json) with an n = 2 case");
  app.add_option("--out", out, "output folder");
  app.add_option("--summarise", summarise, "folders of earlier runs (each with exact.json): one table over them")
      ->excludes("--tables");
  app.add_option("--summary-out", summary_out, "with --summarise: the Markdown file to write");
  app.add_option("--threads", threads, "fork workers");
  app.add_option("--lp-budget", lp_budget, "LPs per endpoint refinement");
  app.add_option("--sweeps", sweeps, "bounding sweeps")->check(CLI::PositiveNumber);
  int short_cap = exact::ExactBoundsOptions{}.short_endpoint_budget_cap;
  double target_ratio = exact::ExactBoundsOptions{}.target_ratio;
  app.add_option("--target-ratio", target_ratio, "an endpoint's refinement stops once outer/inner would be at most this")
      ->check(CLI::Range(1.0, 100.0));
  app.add_option("--short-budget-cap", short_cap,
                 "after the sweeps, an endpoint short of the target gets up to this many times --lp-budget (1 = off)")
      ->check(CLI::PositiveNumber);
  app.add_option("--samples", samples,
                 "another record length than the committed run's (cost against N): the start box is then an assumed "
                 "prior box, not proven for this record")
      ->check(CLI::PositiveNumber);
  app.add_option("--seed", seed,
                 "another noise realisation than the committed run's (a held-out record): the start box is then an "
                 "assumed prior box, not proven for this record")
      ->check(CLI::PositiveNumber);
  app.add_option("--lp-solver", lp_solver, "LP backend: clp, glpk, ipm or ipm-only")->check([](const std::string& name) {
    std::string error;
    return exact::ValidLpSolverName(name, &error) ? std::string() : error;
  });
  app.add_option("--split", split, "what an endpoint's refinement halves: dynamics, alternate, family or dynamics-gamma")
      ->check([](const std::string& name) {
        exact::EndpointSplit parsed;
        return exact::ParseEndpointSplit(name, &parsed) ? std::string() : "expected dynamics, alternate or family";
      });
  app.add_option("--run-dir", run_dir, "keep the jobs' answers here; a rerun (or a run with more sweeps) reads them");
  app.add_option("--gamma-ratio", gamma_ratio, "how a gamma's bound divides by the b_j: largest, rotate or pooled")
      ->check([](const std::string& text) {
        exact::GammaRatio r;
        return exact::ParseGammaRatio(text, &r) ? std::string() : "expected largest, rotate or pooled, not " + text;
      });
  app.add_option("--parameters", parameters, "intervals to compute (default: all), e.g. gamma2,gamma3")->delimiter(',');
  std::vector<std::string> form_blocks;
  if (exact::FormOptions{}.gain) form_blocks.push_back("gain");
  if (exact::FormOptions{}.shape) form_blocks.push_back("shape");
  if (form_blocks.empty()) form_blocks.push_back("none");
  app.add_option("--input-forms", form_blocks,
                 "forms across D's thin directions over these blocks besides the dynamics: gain (the b_j), shape (the "
                 "gammas) or none")
      ->capture_default_str()
      ->delimiter(',')
      ->check(CLI::IsMember({"gain", "shape", "none"}));
  CLI11_PARSE(app, argc, argv);
  try {
    if (!summarise.empty()) {
      if (summary_out.empty()) throw InputError("--summarise needs --summary-out FILE.md");
      const std::string md = Summary(summarise);
      write_text_atomic(summary_out, md);
      fmt::print("{}", md);
      return 0;
    }
    if (tables.empty() || out.empty()) throw InputError("--tables and --out are required (or --summarise DIR...)");
    // Made before the run, so a folder that cannot be made fails now, not after stage 2.
    std::error_code made;
    std::filesystem::create_directories(out, made);
    if (made) throw InputError(fmt::format("{}: cannot make the output folder ({})", out, made.message()));
    StageOne one = ReadStageOne(tables);
    const bool box_proven = (samples == 0 || samples == one.samples) && (seed == 0 || seed == one.seed);
    if (samples > 0) one.samples = samples;
    if (seed > 0) one.seed = seed;
    const CeroneExample ex = SimulateCeroneExample(one.seed, one.samples, one.snr_db);
    dss::HwData data;
    data.u = ex.u;
    data.y = ex.y;
    data.noise_bound.assign(ex.y.size(), ex.noise_bound);
    exact::ExactBoundsOptions options;
    options.threads = threads;
    options.search.lp_budget = lp_budget;
    exact::ParseEndpointSplit(split, &options.search.split);
    exact::ParseGammaRatio(gamma_ratio, &options.search.gamma_ratio);
    options.run_dir = run_dir;
    options.sweeps = sweeps;
    options.short_endpoint_budget_cap = short_cap;
    options.target_ratio = target_ratio;
    options.lp_solver = lp_solver;
    options.forms.gain = std::count(form_blocks.begin(), form_blocks.end(), "gain") > 0;
    options.forms.shape = std::count(form_blocks.begin(), form_blocks.end(), "shape") > 0;
    options.parameters = parameters;
    const auto s = exact::ComputeExactBounds(options, dss::CeroneExampleStructure(), data, one.box,
                                             [](const exact::ExactBoundsProgress& p) {
                                               fmt::print(stderr, "[{:.0f} s] {} {}/{} {}\n", p.elapsed_seconds, p.phase,
                                                          p.done, p.total, p.detail);
                                             });
    const auto truth = CeroneExample::TrueParameters();
    std::string md = fmt::format(
        "# Exact set D, seed {}, N = {}, {} dB (realised {:.2f} dB), noise bound {:.6g}\n\n"
        "Start box: D^ss(2) at δ = {} from `{}` (stage 1: {:.0f} s wall in that committed run, which may have read "
        "its jobs from a run cache){}. Command: `exact_tables --tables {} --out {} --threads {} --lp-budget {} "
        "--sweeps {} --short-budget-cap {} --target-ratio {} --lp-solver {} --split {} --gamma-ratio {}{}`.\n\n",
        one.seed, one.samples, one.snr_db, ex.snr_db, ex.noise_bound, one.order, tables, one.seconds,
        box_proven ? "" : fmt::format("; that run's record is not this one, so here the box is an assumed prior box "
                                      "(the intervals bound D inside it), not a proven one"),
        tables, out, threads, lp_budget, sweeps, short_cap, target_ratio, lp_solver, split, gamma_ratio,
        (samples > 0 ? fmt::format(" --samples {}", samples) : std::string()) +
            (seed > 0 ? fmt::format(" --seed {}", seed) : std::string()) +
            fmt::format(" --input-forms {}", fmt::join(form_blocks, ",")));
    md += Table(s, one, truth);
    md += fmt::format("\nStage 2: {:.1f} s wall on {} (prune {:.1f} s, inner hull {:.1f} s, bound {:.1f} s); {} "
                      "levels, {} boxes tested, {} pruned; {} sweeps{}; {} LPs of {} x {} ({} nonzeros), {} not optimal. "
                      "Assumption on the result: {}.\n",
                      s.wall_seconds, s.executor, s.prune_seconds, s.inner_seconds, s.bound_seconds, s.prune_levels,
                      s.boxes_evaluated, s.boxes_pruned, s.sweeps, s.closing_pass ? " and a closing pass" : "", s.lps, s.lp_rows, s.lp_cols, s.lp_nonzeros, s.lp_failures,
                      s.assumption.holds ? "holds" : "not shown");
    nlohmann::json j = s.to_json();
    j["stage1"] = {{"tables", tables}, {"seconds", one.seconds}, {"start_box_proven_for_this_record", box_proven}};
    j["realisation"] = {{"seed", one.seed}, {"samples", one.samples}, {"snr_db", one.snr_db}, {"realised_snr_db", ex.snr_db}};
    write_text_atomic(out + "/exact_table.md", md);
    write_text_atomic(out + "/exact.json", j.dump(2) + "\n");
    fmt::print("{}", md);
    return 0;
  } catch (const InputError& e) {
    fmt::print(stderr, "error: {}\n", e.what());
    return 2;
  }
}
