// summary.md and the gnuplot plots of a comparison study.
#include <cstdlib>
#include <filesystem>
#include <fstream>

#include <fmt/format.h>

#include "compare/methods.hpp"
#include "compare/study.hpp"
#include "core/atomic_write.hpp"
#include "core/output_files.hpp"

namespace hw::compare {
namespace {

using nlohmann::json;

const char* QuantityLabel(const std::string& q) {
  if (q == "static_rms_pct") return "static curve RMS error [% of range]";
  if (q == "static_max_pct") return "static curve max error [% of range]";
  if (q == "freq_max_error") return "normalised |G| max error";
  if (q == "freq_rms_error") return "normalised |G| RMS error";
  if (q == "phase_max_error_rad") return "phase max error [rad]";
  if (q == "fit_pct") return "validation fit [%] (worst = lowest)";
  return "?";
}

const std::vector<std::string>& QuantityOrder() {
  static const std::vector<std::string> q = {"static_rms_pct", "static_max_pct", "freq_max_error",
                                             "freq_rms_error", "phase_max_error_rad", "fit_pct"};
  return q;
}

std::string G(double v) { return fmt::format("{:.4g}", v); }

// Text inside a Markdown table cell: '|' would end the cell (as in "|G|") and a newline the row.
std::string Cell(const std::string& text) {
  std::string out;
  for (char c : text) {
    if (c == '|') out += "\\|";
    else if (c == '\n' || c == '\r') out += ' ';
    else out += c;
  }
  return out;
}

// Why the set-membership curves may be flat: they are drawn from the model at the intervals' centres.
constexpr const char* kMidpointNote =
    "The set-membership curves (static curve, frequency response, validation fit) are those of the model at the "
    "centres of its guaranteed intervals: a point inside the intervals, not an estimate the method makes. When the "
    "intervals span most of the prior box, their centres lie near 0 (gamma, b near 0), so the static curve is "
    "nearly flat; that shows how wide the intervals are, not a fitted model.";

}  // namespace

std::string SummaryMarkdown(const json& s) {
  std::string md = fmt::format("# Comparison study: {}\n\n{}\n\n", s.value("scenario", ""), s.value("description", ""));
  md += fmt::format("{} runs, seed {}, {} worker processes, wall time {:.1f} s ({} runs computed, {} resumed).\n\n",
                    s.value("runs", 0), s.value("seed", 0), s.value("jobs", 0), s.value("wall_seconds", 0.0),
                    s.value("runs_computed", 0), s.value("runs_resumed", 0));
  md += "## Methods\n\n| method | applies | runs ok | failed | note |\n|---|---|---|---|---|\n";
  for (const auto& [name, m] : s["methods"].items()) {
    if (!m.value("applicable", false)) {
      md += fmt::format("| {} | no | - | - | {} |\n", Cell(name), Cell(m.value("reason", "")));
      continue;
    }
    std::string note;
    for (const auto& f : m["failures"]) note += fmt::format("run {}: {}; ", f["run"].get<int>(), f["message"].get<std::string>());
    md += fmt::format("| {} | yes | {} | {} | {} |\n", Cell(name), m.value("runs_ok", 0), m["failures"].size(), Cell(note));
  }
  md += "\n## Accuracy (normalisation-free quantities)\n\n"
        "| method | quantity | runs | mean | std | worst |\n|---|---|---|---|---|---|\n";
  for (const auto& [name, m] : s["methods"].items()) {
    if (!m.value("applicable", false)) continue;
    for (const auto& q : QuantityOrder()) {
      if (m.contains("quantities") && m["quantities"].contains(q)) {
        const auto& st = m["quantities"][q];
        md += fmt::format("| {} | {} | {} | {} | {} | {} |\n", Cell(name), Cell(QuantityLabel(q)), st["n"].get<int>(),
                          G(st["mean"]), G(st["std"]), G(st["worst"]));
      } else if (m.contains("not_available") && m["not_available"].contains(q)) {
        md += fmt::format("| {} | {} | 0 | n/a | | {} |\n", Cell(name), Cell(QuantityLabel(q)),
                          Cell(m["not_available"][q].get<std::string>()));
      }
    }
  }
  for (const auto& [name, m] : s["methods"].items()) {
    if (!m.contains("coverage")) continue;
    const auto& c = m["coverage"];
    md += fmt::format("\n## Guaranteed intervals ({}): coverage of the truth\n\n"
                      "{} of {} intervals contain the truth; {} of {} runs had every endpoint guaranteed "
                      "(the rest used conservative, still valid, fallbacks).\n\n"
                      "| parameter | truth | covered / runs | mean width | std width | max width |\n"
                      "|---|---|---|---|---|---|\n",
                      name, c["covered"].get<int>(), c["total"].get<int>(), c["runs_all_guaranteed"].get<int>(),
                      c["runs"].get<int>());
    for (const auto& [p, v] : c["per_parameter"].items())
      md += fmt::format("| {} | {} | {} / {} | {} | {} | {} |\n", Cell(p), G(v["truth"]), v["covered"].get<int>(),
                        v["runs"].get<int>(), G(v["width"]["mean"]), G(v["width"]["std"]), G(v["width"]["worst"]));
  }
  bool header = false;
  for (const auto& [name, m] : s["methods"].items()) {
    if (!m.contains("inside_setmembership_intervals")) continue;
    if (!header) {
      md += "\n## Point estimates inside the guaranteed intervals\n\n"
            "Point estimates mapped into the set-membership parametrisation (gamma_1 = alpha_1 = 1).\n\n"
            "| method | parameter | inside / runs | mapping | max projection residual |\n|---|---|---|---|---|\n";
      header = true;
    }
    for (const auto& [p, v] : m["inside_setmembership_intervals"].items())
      md += fmt::format("| {} | {} | {} / {} | {} | {} |\n", Cell(name), Cell(p), v["inside"].get<int>(),
                        v["runs"].get<int>(), Cell(v["mapping"].get<std::string>()), G(v["max_projection_residual"]));
  }
  md += "\n## Run time per method and run\n\n| method | runs | mean [s] | std [s] | max [s] | total [s] |\n"
        "|---|---|---|---|---|---|\n";
  for (const auto& [name, m] : s["methods"].items())
    if (m.contains("time"))
      md += fmt::format("| {} | {} | {} | {} | {} | {} |\n", Cell(name), m["time"]["n"].get<int>(), G(m["time"]["mean"]),
                        G(m["time"]["std"]), G(m["time"]["max"]), G(m["time"]["total"]));
  md += fmt::format("\nTimes are wall seconds inside a worker process ({} workers sharing the machine).\n",
                    s.value("jobs", 0));
  if (s["methods"].contains("setmembership") && s["methods"]["setmembership"].contains("quantities"))
    md += fmt::format("\n{}\n", kMidpointNote);
  if (!s.value("coverage_ok", true))
    md += fmt::format("\n**COVERAGE FAILURE: a guaranteed interval excluded the truth (see {}/*.json).**\n",
                      s.value("run_files", "runs"));
  if (s.contains("plots_note") && !s["plots_note"].get<std::string>().empty())
    md += "\nPlots: " + s["plots_note"].get<std::string>() + "\n";
  return md;
}

namespace {
// Legend entry of a method's curves; the set-membership one says what its curve is.
std::string CurveTitle(const std::string& method) {
  if (method == "setmembership") return "setmembership: model at the interval centres, every run (flat = wide intervals)";
  if (method == "exact") return "exact: model at the centres of the exact-set intervals, every run";
  return method + " (every run)";
}
}  // namespace

std::string WritePlots(const std::string& dir, const Scenario& scenario, const std::vector<json>& runs,
                       const json& summary) {
  namespace fs = std::filesystem;
  const std::string pd = dir + "/plots";
  fs::create_directories(pd);
  std::vector<std::string> methods;
  for (const auto& [name, m] : summary["methods"].items())
    if (m.value("applicable", false)) methods.push_back(name);
  std::string gp = "set terminal pngcairo size 900,650\nset grid\nset key below\n";
  // 1. Error distributions: one panel per quantity, each method's runs as jittered points.
  for (const auto& q : QuantityOrder()) {
    std::string plot;
    for (std::size_t k = 0; k < methods.size(); ++k) {
      std::string data;
      for (const auto& r : runs) {
        const auto& m = r["methods"][methods[k]];
        if (m.contains("quantities") && m["quantities"].contains(q))
          data += fmt::format("{} {}\n", k + 1 + 0.3 * ((r["run"].get<int>() * 37 % 11) / 10.0 - 0.5),
                              m["quantities"][q].get<double>());
      }
      if (data.empty()) continue;
      const std::string f = fmt::format("{}/err_{}_{}.dat", pd, q, methods[k]);
      write_text_atomic(f, data);
      plot += fmt::format("{}'err_{}_{}.dat' using 1:2 with points pt 7 title '{}'", plot.empty() ? "" : ", ", q,
                          methods[k], methods[k]);
    }
    if (plot.empty()) continue;
    std::string xt;
    for (std::size_t k = 0; k < methods.size(); ++k) xt += fmt::format("{}'{}' {}", k ? ", " : "", methods[k], k + 1);
    gp += fmt::format("set output 'errors_{}.png'\nset title '{} ({} runs)'\nset xrange [0.5:{}.5]\n"
                      "set xtics ({})\nunset logscale\nplot {}\n",
                      q, QuantityLabel(q), runs.size(), methods.size(), xt, plot);
  }
  gp += "set autoscale x\nset xtics auto\n";
  // 2. Intervals with the truth and the point estimates, relative to the truth.
  std::string iv, pts;
  std::vector<std::string> names;
  for (const auto& r : runs) {
    if (!r["methods"].contains("setmembership") || !r["methods"]["setmembership"].contains("intervals")) continue;
    const auto& sm = r["methods"]["setmembership"];
    const int run = r["run"];
    for (const auto& v : sm["intervals"]) {
      const std::string n = v["name"];
      auto it = std::find(names.begin(), names.end(), n);
      if (it == names.end()) it = names.insert(names.end(), n);
      // Relative to the prior box half-width, so that every parameter's interval fits one scale.
      const double t = v["truth"], scale = 0.5 * (v["box"][1].get<double>() - v["box"][0].get<double>());
      const double x = (it - names.begin()) + 1 + 0.6 * (run + 0.5) / runs.size() - 0.3;
      const double lo = (v["lower"].get<double>() - t) / scale, hi = (v["upper"].get<double>() - t) / scale;
      iv += fmt::format("{} {} {} {}\n", x, 0.5 * (lo + hi), lo, hi);
      for (const auto& [mname, m] : r["methods"].items())
        if (m.contains("inside_setmembership_intervals"))
          for (const auto& p : m["inside_setmembership_intervals"]["parameters"])
            if (p["name"] == n) pts += fmt::format("{} {}\n", x, (p["value"].get<double>() - t) / scale);
    }
  }
  if (!iv.empty()) {
    write_text_atomic(pd + "/intervals.dat", iv);
    std::string xt;
    for (std::size_t k = 0; k < names.size(); ++k) xt += fmt::format("{}'{}' {}", k ? ", " : "", names[k], k + 1);
    std::string plot = "'intervals.dat' using 1:2:3:4 with yerrorbars pt 0 lc rgb '#1f77b4' title 'guaranteed interval "
                       "(set-membership)', 0 with lines lc rgb 'black' title 'truth'";
    if (!pts.empty()) {
      write_text_atomic(pd + "/point_estimates.dat", pts);
      plot += ", 'point_estimates.dat' using 1:2 with points pt 7 lc rgb '#d62728' title 'esmaeilani (mapped)'";
    }
    gp += fmt::format("set output 'intervals.png'\nset title 'Intervals per run: (value - truth) / prior box half-width'\n"
                      "set xtics ({})\nplot {}\nset xtics auto\n", xt, plot);
  }
  // 3. Static curves and 4. normalised frequency responses overlaid (truth and every run's estimate).
  const json truth = TruthCurves(scenario);
  auto curve_file = [&](const std::string& name, const std::vector<double>& x, const std::vector<double>& y) {
    std::string t;
    for (std::size_t i = 0; i < x.size() && i < y.size(); ++i) t += fmt::format("{} {}\n", x[i], y[i]);
    write_text_atomic(pd + "/" + name, t);
  };
  const bool backlash = scenario.kind == PlantKind::kBacklash;
  std::string splot, fplot;
  if (backlash) {
    curve_file("static_truth_up.dat", truth["static_u_up"], truth["static_up"]);
    curve_file("static_truth_down.dat", truth["static_u_down"], truth["static_down"]);
    splot = "'static_truth_up.dat' with lines lw 3 lc rgb 'black' title 'truth (ascending border)', "
            "'static_truth_down.dat' with lines lw 3 dt 2 lc rgb 'black' title 'truth (descending border)'";
  } else {
    curve_file("static_truth.dat", truth["static_u"], truth["static_y"]);
    splot = "'static_truth.dat' with lines lw 3 lc rgb 'black' title 'truth'";
  }
  curve_file("freq_truth.dat", truth["omega"], truth["gain"]);
  fplot = "'freq_truth.dat' with lines lw 3 lc rgb 'black' title 'truth'";
  const char* colours[] = {"#1f77b4", "#d62728", "#2ca02c"};
  for (std::size_t k = 0; k < methods.size(); ++k) {
    std::string sd, fd;
    for (const auto& r : runs) {
      const auto& m = r["methods"][methods[k]];
      if (!m.contains("curves")) continue;
      const auto& c = m["curves"];
      if (c.contains("static_y"))
        for (std::size_t i = 0; i < c["static_u"].size(); ++i)
          sd += fmt::format("{} {}\n", c["static_u"][i].get<double>(), c["static_y"][i].get<double>());
      if (c.contains("static_up")) {
        for (std::size_t i = 0; i < c["static_u_up"].size(); ++i)
          sd += fmt::format("{} {}\n", c["static_u_up"][i].get<double>(), c["static_up"][i].get<double>());
        sd += "\n";
        for (std::size_t i = 0; i < c["static_u_down"].size(); ++i)
          sd += fmt::format("{} {}\n", c["static_u_down"][i].get<double>(), c["static_down"][i].get<double>());
      }
      sd += "\n";
      if (c.contains("omega"))
        for (std::size_t i = 0; i < c["omega"].size(); ++i)
          fd += fmt::format("{} {}\n", c["omega"][i].get<double>(), c["gain"][i].get<double>());
      fd += "\n";
    }
    const std::string style = backlash ? "points pt 7" : "lines lw 1";
    if (!sd.empty() && sd.find_first_not_of('\n') != std::string::npos) {
      write_text_atomic(fmt::format("{}/static_{}.dat", pd, methods[k]), sd);
      splot += fmt::format(", 'static_{}.dat' with lines lw 1 lc rgb '{}' title '{}'", methods[k], colours[k % 3],
                           CurveTitle(methods[k]));
    }
    if (!fd.empty() && fd.find_first_not_of('\n') != std::string::npos) {
      write_text_atomic(fmt::format("{}/freq_{}.dat", pd, methods[k]), fd);
      fplot += fmt::format(", 'freq_{}.dat' with {} lc rgb '{}' title '{}'", methods[k], style, colours[k % 3],
                           CurveTitle(methods[k]));
    }
  }
  // gnuplot's enhanced text reads '_' as a subscript of one character: y_{ss} is "y" with subscript "ss".
  gp += fmt::format("set output 'static_curves.png'\nset title 'Static input-output curve y_{{ss}}(u)'\n"
                    "set xlabel 'u'\nset ylabel 'y_{{ss}}'\nplot {}\n", splot);
  gp += fmt::format("set output 'frequency_response.png'\nset title '{}'\n"
                    "set xlabel 'omega [rad/{}]'\nset ylabel 'normalised gain (log scale)'\nset logscale y\n{}plot {}\n",
                    backlash ? "Normalised |G(jw)|/|G(0)|" : "Normalised |G(e^{jw})|/|G(1)|", backlash ? "s" : "sample",
                    backlash ? "set logscale x\n" : "", fplot);
  write_text_atomic(pd + "/plots.gp", gp);
  if (!GnuplotAvailable()) return "gnuplot not found: data and plots/plots.gp written, PNGs not made";
  return RunGnuplot(pd, "plots.gp");
}

}  // namespace hw::compare
