// Reproduces Tables I-III of paper 001 (Cerone, Piga, Regruto): parameter intervals of the Section VI
// example for dynamic horizons n = 2 and n = 3 at relaxation order delta, side by side with the paper's.
//
//   cerone_tables [--out DIR] [--seed S] [--samples N] [--order D] [--horizons 2,3] [--solver sdpa]
//                 [--threads T] [--run-dir DIR] [--no-verify]
// Every endpoint is verified rigorously by default (sdp/verified_bound.hpp); the tables give the verification
// status and the correction (how far verification moved the endpoint from the solver's floating-point value).
// Writes DIR/tables.md, DIR/tables.json, DIR/intervals.png (gnuplot), and prints the tables.
#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <map>

#include <CLI/CLI.hpp>
#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "core/cerone_example.hpp"
#include "core/csv_table.hpp"
#include "relax/set_membership.hpp"

namespace {

struct PaperRow {
  double lower, upper, half;
};
// Tables I-III of the paper (delta = 3): parameter -> (n -> row).
const std::map<std::string, std::map<int, PaperRow>> kPaper = {
    {"gamma2", {{2, {0.273, 0.547, 0.137}}, {3, {0.313, 0.476, 0.082}}}},
    {"gamma3", {{2, {-0.234, -0.043, 0.095}}, {3, {-0.124, -0.071, 0.023}}}},
    {"alpha2", {{2, {0.523, 1.147, 0.312}}, {3, {0.664, 0.931, 0.133}}}},
    {"alpha3", {{2, {2.432, 3.839, 0.704}}, {3, {2.914, 3.521, 0.304}}}},
    {"a1", {{2, {1.556, 1.999, 0.221}}, {3, {1.612, 1.934, 0.161}}}},
    {"a2", {{2, {0.695, 0.999, 0.152}}, {3, {0.785, 0.968, 0.092}}}},
    {"b1", {{2, {1.138, 2.194, 0.528}}, {3, {1.345, 1.877, 0.266}}}},
    {"b2", {{2, {1.572, 2.718, 0.595}}, {3, {1.875, 2.331, 0.228}}}},
};

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Reproduce Tables I-III of Cerone, Piga, Regruto (set-membership HW identification)"};
  std::string out = "out/cerone", solver = "sdpa", run_dir = "runs/cerone", horizons_text = "2,3";
  uint64_t seed = 1;
  int samples = 1000, order = 3, threads = 0, contraction_passes = 0;
  bool verify = true;
  app.add_option("--out", out, "output directory");
  app.add_option("--seed", seed, "noise/input seed");
  app.add_option("--samples", samples, "N");
  app.add_option("--order", order, "relaxation order delta");
  app.add_option("--horizons", horizons_text, "comma list of dynamic horizons n");
  app.add_option("--solver", solver, "csdp or sdpa");
  app.add_option("--threads", threads, "parallel SDP jobs (0 = all cores)");
  app.add_option("--contract-passes", contraction_passes, "cheap passes in contracted boxes (0 = off)");
  app.add_option("--run-dir", run_dir, "resumable cache of finished SDPs ('' to disable)");
  app.add_flag("--verify,!--no-verify", verify, "verify every bound rigorously (default on)");
  CLI11_PARSE(app, argc, argv);
  std::vector<int> horizons;
  for (char c : horizons_text)
    if (c >= '1' && c <= '9') horizons.push_back(c - '0');

  std::filesystem::create_directories(out);
  const auto ex = hw::SimulateCeroneExample(seed, samples);
  const auto truth = hw::CeroneExample::TrueParameters();
  fmt::print("Example of paper 001, Section VI: N = {}, seed {}, noise bound {:.6g} (realised SNR_w {:.2f} dB)\n",
             samples, seed, ex.noise_bound, ex.snr_db);
  const hw::relax::HwStructure structure = hw::relax::CeroneExampleStructure();
  hw::relax::HwData data{ex.u, ex.y, std::vector<double>(ex.y.size(), ex.noise_bound), "cerone2011 example"};

  nlohmann::json report;
  report["example"] = {{"seed", seed}, {"samples", samples}, {"noise_bound", ex.noise_bound}, {"snr_db", ex.snr_db},
                       {"order", order}, {"solver", solver}, {"verify", verify}};
  std::string md = fmt::format(
      "# Paper 001, Tables I-III reproduced\n\nN = {}, seed {}, uniform noise bound {:.6g} (realised SNR_w {:.2f} dB), "
      "relaxation order delta = {}, solver {}, prior box |p_i| <= 10, verification {}.\n\n",
      samples, seed, ex.noise_bound, ex.snr_db, order, solver, verify ? "on" : "off");
  std::string plot_data;
  bool all_inside = true;
  int row = 0;
  for (int n : horizons) {
    hw::relax::HwOuterSet set(structure, data, n, std::vector<std::pair<double, double>>(8, {-10.0, 10.0}));
    hw::relax::BoundsOptions options;
    options.order = order;
    options.solver = solver;
    options.threads = threads;
    options.contraction_passes = contraction_passes;
    options.run_dir = run_dir;
    options.generation.verify.enabled = verify;
    const auto summary = hw::relax::ComputeBounds(options, set, [](const hw::relax::BoundsProgress& p) {
      fmt::print(stderr, "\r[{}] {}/{} jobs, elapsed {:.0f} s, ETA {:.0f} s   ", p.phase, p.done, p.total,
                 p.elapsed_seconds, p.eta_seconds);
      if (p.done == p.total) fmt::print(stderr, "\n");
    });
    md += fmt::format("## Horizon n = {}\n\n", n);
    md += "| parameter | ours lower | ours upper | paper lower | paper upper | true | our half-width | paper half-width | ratio "
          "| status | verified | correction lower / upper |\n";
    md += "|---|---|---|---|---|---|---|---|---|---|---|---|\n";
    double max_correction = 0.0;
    int unverified = 0;
    nlohmann::json rows = nlohmann::json::array();
    for (std::size_t k = 0; k < summary.intervals.size(); ++k) {
      const auto& iv = summary.intervals[k];
      const auto& paper = kPaper.at(iv.name).at(n);
      const bool inside = iv.lower.value <= truth[k] && truth[k] <= iv.upper.value;
      all_inside = all_inside && inside;
      const double ratio = iv.half_width() / paper.half;
      const std::string status = (iv.lower.status == "guaranteed" && iv.upper.status == "guaranteed")
                                     ? "guaranteed"
                                     : iv.lower.status + "/" + iv.upper.status;
      const std::string verified = iv.lower.verification == iv.upper.verification
                                       ? iv.lower.verification
                                       : iv.lower.verification + "/" + iv.upper.verification;
      max_correction = std::max({max_correction, iv.lower.correction, iv.upper.correction});
      unverified += (iv.lower.verification == "unverified") + (iv.upper.verification == "unverified");
      md += fmt::format("| {} | {:.3f} | {:.3f} | {:.3f} | {:.3f} | {} | {:.3f} | {:.3f} | {:.2f} | {}{} | {} | {:.1e} / {:.1e} |\n",
                        iv.name, iv.lower.value, iv.upper.value, paper.lower, paper.upper, truth[k], iv.half_width(),
                        paper.half, ratio, status, inside ? "" : " TRUTH OUTSIDE", verified, iv.lower.correction,
                        iv.upper.correction);
      rows.push_back({{"parameter", iv.name}, {"lower", iv.lower.value}, {"upper", iv.upper.value},
                      {"paper_lower", paper.lower}, {"paper_upper", paper.upper}, {"true", truth[k]},
                      {"half_width", iv.half_width()}, {"paper_half_width", paper.half}, {"ratio", ratio},
                      {"truth_inside", inside}, {"lower_status", iv.lower.status}, {"upper_status", iv.upper.status},
                      {"tight", iv.lower.tight && iv.upper.tight}, {"lower_verification", iv.lower.verification},
                      {"upper_verification", iv.upper.verification}, {"lower_correction", iv.lower.correction},
                      {"upper_correction", iv.upper.correction}});
      plot_data += fmt::format("{} {} {} {} {} {} {} {}\n", row++, iv.name + "_n" + std::to_string(n),
                               (iv.lower.value - truth[k]) / paper.half, (iv.upper.value - truth[k]) / paper.half,
                               (paper.lower - truth[k]) / paper.half, (paper.upper - truth[k]) / paper.half, 0, n);
    }
    md += fmt::format("\nOrthants: {} total, {} proven empty, {} solved, {} failed. {} relaxation jobs, {} SDP solves, "
                      "largest SDP {} moments / {} blocks, median SDP {:.1f} s, wall time {:.1f} s.\n\n",
                      summary.orthants_total, summary.orthants_empty, summary.orthants_solved, summary.orthants_failed,
                      summary.sdp_jobs, summary.sdp_solves, summary.largest_moments, summary.largest_blocks,
                      summary.median_solve_seconds, summary.wall_seconds);
    if (verify)
      md += fmt::format("Verification: {} unverified endpoints, largest correction {:.2e}; {:.2f} s of verification "
                        "(perturbed re-solves included) for {:.1f} s of SDP solves ({:.2f}%).\n\n",
                        unverified, max_correction, summary.verify_seconds, summary.solve_seconds,
                        summary.solve_seconds > 0 ? 100 * summary.verify_seconds / summary.solve_seconds : 0.0);
    auto j = summary.to_json();
    j["rows"] = rows;
    report["horizons"][std::to_string(n)] = j;
  }
  report["all_truth_inside"] = all_inside;
  hw::write_text_atomic(out + "/tables.md", md);
  hw::write_text_atomic(out + "/tables.json", report.dump(2) + "\n");
  hw::write_text_atomic(out + "/intervals.dat", plot_data);
  hw::write_text_atomic(
      out + "/intervals.gp",
      "set terminal pngcairo size 1000,600\nset output 'intervals.png'\n"
      "set title 'Intervals minus truth, in units of the paper half-width (ours: thick, paper: thin)'\n"
      "set xtics rotate by -45\nset yrange [-3:3]\nset grid\n"
      "plot 'intervals.dat' using 1:3:3:4:xtic(2) with yerrorbars lw 3 title 'hwbounds', "
      "'' using ($1+0.25):5:5:6 with yerrorbars lw 1 title 'paper', 0 with lines lc rgb 'black' title 'truth'\n");
  const std::string cmd = fmt::format("cd '{}' && gnuplot intervals.gp 2>/dev/null", out);
  if (std::system(cmd.c_str()) != 0) fmt::print(stderr, "gnuplot failed; the data are in {}/intervals.dat\n", out);
  fmt::print("{}", md);
  fmt::print("wrote {}/tables.md, tables.json, intervals.png\n", out);
  return all_inside ? 0 : 3;
}
