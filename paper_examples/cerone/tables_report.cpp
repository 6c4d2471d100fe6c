#include "paper_examples/cerone/tables_report.hpp"

#include <cmath>
#include <cstdlib>
#include <map>
#include <set>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "core/csv_table.hpp"
#include "core/output_files.hpp"
#include "paper_examples/cerone/paper_table.hpp"

namespace hw::cerone {

namespace {

std::string Interval(double lo, double hi) { return fmt::format("[{:.4f}, {:.4f}]", lo, hi); }
std::string Number(double v, const char* spec = "{:.4f}") {
  return std::isfinite(v) ? fmt::format(fmt::runtime(spec), v) : "–";
}

double TruthOf(const TableCase& c, const std::string& name) {
  for (std::size_t k = 0; k < c.names.size(); ++k)
    if (c.names[k] == name) return c.truth[k];
  return NAN;
}

// The realisations in the order they were run: (SNR, seed) -> the cases of its horizons.
std::map<std::pair<double, uint64_t>, std::vector<const TableCase*>> ByRealisation(const std::vector<TableCase>& cases) {
  std::map<std::pair<double, uint64_t>, std::vector<const TableCase*>> groups;
  for (const auto& c : cases) groups[{c.snr_db, c.seed}].push_back(&c);
  return groups;
}

bool ReachesBox(const InnerInterval& iv, double box) {
  return iv.found && (iv.lower <= -box * (1 - 1e-9) || iv.upper >= box * (1 - 1e-9));
}

// One row of a case's table: a parameter's inner hull, the paper's interval, and each order's outer interval.
std::string MarkdownRow(const TableCase& c, const InnerInterval& inner, const std::vector<int>& orders, double box) {
  const auto paper = PaperTableInterval(inner.name, c.horizon);
  const double paper_half = paper ? paper->half_width() : NAN;
  const double inner_half = inner.found ? inner.half_width() : NAN;
  std::string row = fmt::format("| {} | {:.3f} | {} | {}{} | {} | {} |", inner.name, TruthOf(c, inner.name),
                                paper ? Interval(paper->lower, paper->upper) : "–",
                                inner.found ? Interval(inner.lower, inner.upper) : "none found",
                                ReachesBox(inner, box) ? " (box)" : "", Number(paper_half), Number(inner_half));
  for (int order : orders) {
    const auto run = c.outer.find(order);
    const auto* outer = run == c.outer.end() ? nullptr : FindInterval(run->second, inner.name);
    if (!outer) {
      row += " not run | – | – | – |";
      continue;
    }
    const bool sure = outer->lower.status == "guaranteed" && outer->upper.status == "guaranteed";
    row += fmt::format(" {}{} | {} | {} | {} |", Interval(outer->lower.value, outer->upper.value), sure ? "" : " *",
                       Number(outer->half_width()), Number(outer->half_width() / inner_half, "{:.2f}"),
                       Number(outer->half_width() / paper_half, "{:.2f}"));
  }
  return row + "\n";
}

std::string CaseNotes(const TableCase& c) {
  std::string notes = fmt::format("Inner hull: {} certified witnesses ({} of them the engine's feasible points) from {} "
                                  "local solves, {:.1f} s.", c.inner.witnesses, c.inner.given_witnesses,
                                  c.inner.local_solves, c.inner.seconds);
  if (c.box_from_horizon > 0 && !c.outer.empty())
    notes += fmt::format(" The outer runs started in the box of the n = {} outer intervals (D^ss({}) lies inside "
                         "D^ss({})), so the n = {} outer intervals lie inside those by construction.",
                         c.box_from_horizon, c.horizon, c.box_from_horizon, c.horizon);
  for (const auto& [order, run] : c.outer)
    notes += fmt::format(" Order {}: {}, solver {}, {} SDP solves, {:.1f} s{}{}.", order, run.relaxation, run.solver,
                         run.sdp_solves, run.wall_seconds,
                         run.jobs_from_cache > 0 ? fmt::format(" ({} jobs read from the run cache)", run.jobs_from_cache) : "",
                         run.all_guaranteed() ? "" : ", some endpoints conservative (*)");
  return notes + "\n\n";
}

std::string CaseTable(const TableCase& c, const std::vector<int>& orders, double box) {
  std::string md = fmt::format("### n = {}\n\n| parameter | truth | paper | inner hull | paper half | inner half |", c.horizon);
  std::string rule = "|---|---|---|---|---|---|";
  for (int order : orders) {
    md += fmt::format(" outer δ={} | half | outer/inner | outer/paper |", order);
    rule += "---|---|---|---|";
  }
  md += "\n" + rule + "\n";
  for (const auto& inner : c.inner.intervals) md += MarkdownRow(c, inner, orders, box);
  return md + "\n" + CaseNotes(c);
}

std::string ViolationsMarkdown(const std::vector<Violation>& violations) {
  if (violations.empty()) return "**Every property holds on every table below.**\n\n";
  std::string md = fmt::format("**{} property violations:**\n\n", violations.size());
  for (const auto& v : violations)
    md += fmt::format("- {} ({}): {} (excess {:.3g})\n", v.property, v.parameter, v.text, v.excess);
  return md + "\n";
}

std::string EquivalentMarkdown(const EquivalentSnrResult& e, uint64_t seed) {
  std::string md = fmt::format("## Equivalent noise level (seed {})\n\n{}.\n\n", seed, EquivalentSnrCriterionText());
  md += e.bracketed ? fmt::format("Closest: **{:.2f} dB** (criterion {:.3f}).\n\n", e.best.snr_db, e.best.criterion)
                    : fmt::format("Not bracketed by the range: the closest end is {:.2f} dB (criterion {:.3f}).\n\n",
                                  e.best.snr_db, e.best.criterion);
  // With several tables, each one's own criterion shows where that table alone would cross 0.
  std::vector<int> own = e.best.horizons();
  if (own.size() < 2) own.clear();
  md += "| SNR [dB] | criterion |";
  for (int n : own) md += fmt::format(" n = {} only |", n);
  md += "\n|---|---|";
  for (std::size_t i = 0; i < own.size(); ++i) md += "---|";
  md += "\n";
  for (const auto& s : e.evaluations) {
    md += fmt::format("| {:.2f} | {:.3f} |", s.snr_db, s.criterion);
    for (int n : own) md += fmt::format(" {:.3f} |", s.criterion_of(n));
    md += "\n";
  }
  md += fmt::format("\nAt {:.2f} dB:\n\n| n | parameter | inner half | paper half | ratio |\n|---|---|---|---|---|\n",
                    e.best.snr_db);
  for (const auto& r : e.best.ratios)
    md += fmt::format("| {} | {} | {:.4f} | {:.4f} | {:.2f} |\n", r.horizon, r.parameter, r.inner_half, r.paper_half,
                      r.ratio());
  return md + "\n";
}

template <class T>
std::string ListText(const std::vector<T>& values) {
  return values.empty() ? "none" : fmt::format("{}", fmt::join(values, ","));
}

std::string SettingsMarkdown(const TablesReport& r) {
  const auto& o = r.options;
  return fmt::format(
      "Command: `{}`\n\nN = {}, horizons {}, orders {} (outer intervals computed at orders {} and SNR {} dB), seeds "
      "{}, prior box ±{:g}, solver {}, data-row block order cap {}, endpoint refinements {}, verification {}. Inner hull: local optimisation "
      "from the truth, {} pseudo-random starts per objective and {} restart round(s) from other witnesses and from "
      "the outer runs' certified feasible points (every live orthant's); every witness certified by evaluating every inequality of its orthant with a rounding allowance. Outer "
      "intervals marked * have a conservative endpoint; an inner hull marked (box) reaches the prior box.\n\n",
      r.command, o.samples, ListText(o.horizons), ListText(o.orders), ListText(o.outer_orders), ListText(o.outer_snrs),
      ListText(o.seeds), o.box, o.bounds.solver, o.bounds.generation.block_order_cap, o.bounds.endpoint_refinements,
      o.bounds.generation.verify.enabled ? "on" : "off", o.inner.random_starts, o.inner.restart_rounds);
}

}  // namespace

std::string TablesMarkdown(const TablesReport& report) {
  std::string md = "# Paper 001, Tables I-III: outer intervals, inner hulls and the paper's intervals\n\n";
  md += SettingsMarkdown(report) + PropertiesText(report.options.tolerance) + "\n\n" + ViolationsMarkdown(report.violations);
  for (const auto& [key, group] : ByRealisation(report.cases)) {
    const TableCase& first = *group.front();
    md += fmt::format("## SNR_w {:g} dB (realised {:.2f} dB), seed {}, noise bound {:.6g}\n\n", key.first,
                      first.realised_snr_db, key.second, first.noise_bound);
    for (const auto* c : group) md += CaseTable(*c, report.options.orders, report.options.box);
  }
  if (report.equivalent) md += EquivalentMarkdown(*report.equivalent, report.options.equivalent_seed);
  return md;
}

namespace {

nlohmann::json WitnessJson(const Witness& w) {
  return {{"point", w.point}, {"orthant", w.orthant}, {"certified_slack", w.certified_slack}};
}

nlohmann::json OuterRowJson(const dss::ParameterInterval& outer, double inner_half, double paper_half) {
  return {{"lower", outer.lower.value}, {"upper", outer.upper.value}, {"half_width", outer.half_width()},
          {"ratio_outer_inner", outer.half_width() / inner_half}, {"ratio_outer_paper", outer.half_width() / paper_half},
          {"lower_status", outer.lower.status}, {"upper_status", outer.upper.status},
          {"lower_verification", outer.lower.verification}, {"upper_verification", outer.upper.verification},
          {"tight", outer.lower.tight && outer.upper.tight}};
}

nlohmann::json RowJson(const TableCase& c, const InnerInterval& inner, double box) {
  const auto paper = PaperTableInterval(inner.name, c.horizon);
  const double paper_half = paper ? paper->half_width() : NAN;
  const double inner_half = inner.found ? inner.half_width() : NAN;
  nlohmann::json row = {{"parameter", inner.name}, {"truth", TruthOf(c, inner.name)}, {"inner_found", inner.found},
                        {"inner_reaches_box", ReachesBox(inner, box)}};
  row["paper"] = paper ? nlohmann::json{{"lower", paper->lower}, {"upper", paper->upper}, {"half_width", paper_half}}
                       : nlohmann::json(nullptr);
  if (inner.found)
    row["inner"] = {{"lower", inner.lower}, {"upper", inner.upper}, {"half_width", inner_half},
                    {"ratio_inner_paper", inner_half / paper_half}, {"lower_witness", WitnessJson(inner.lower_witness)},
                    {"upper_witness", WitnessJson(inner.upper_witness)}};
  row["outer"] = nlohmann::json::object();
  for (const auto& [order, run] : c.outer)
    if (const auto* outer = FindInterval(run, inner.name))
      row["outer"][std::to_string(order)] = OuterRowJson(*outer, inner_half, paper_half);
  return row;
}

nlohmann::json CaseJson(const TableCase& c, double box) {
  nlohmann::json rows = nlohmann::json::array(), runs = nlohmann::json::object();
  for (const auto& inner : c.inner.intervals) rows.push_back(RowJson(c, inner, box));
  for (const auto& [order, run] : c.outer) runs[std::to_string(order)] = run.to_json();
  return {{"n", c.horizon}, {"snr_db", c.snr_db}, {"realised_snr_db", c.realised_snr_db},
          {"noise_bound", c.noise_bound}, {"seed", c.seed}, {"samples", c.samples},
          {"inner_hull", {{"witnesses", c.inner.witnesses}, {"given_by_the_engine", c.inner.given_witnesses},
                          {"local_solves", c.inner.local_solves},
                          {"seconds", c.inner.seconds}}},
          {"outer_box", c.outer_box}, {"outer_box_from_horizon", c.box_from_horizon},
          {"rows", rows}, {"outer_runs", runs}};
}

}  // namespace

nlohmann::json TablesJson(const TablesReport& report) {
  const auto& o = report.options;
  nlohmann::json cases = nlohmann::json::array(), violations = nlohmann::json::array();
  for (const auto& c : report.cases) cases.push_back(CaseJson(c, o.box));
  for (const auto& v : report.violations) violations.push_back(v.to_json());
  return {{"command", report.command},
          {"settings", {{"samples", o.samples}, {"horizons", o.horizons}, {"orders", o.orders},
                        {"outer_orders", o.outer_orders}, {"snr_db", o.snrs}, {"outer_snr_db", o.outer_snrs},
                        {"seeds", o.seeds}, {"params", o.params}, {"box", o.box}, {"solver", o.bounds.solver},
                        {"row_block_order", o.bounds.generation.block_order_cap},
                        {"endpoint_refinements", o.bounds.endpoint_refinements},
                        {"verify", o.bounds.generation.verify.enabled}, {"inner_random_starts", o.inner.random_starts},
                        {"inner_restart_rounds", o.inner.restart_rounds}, {"tolerance", o.tolerance},
                        {"nest_horizons", o.nest_horizons}}},
          {"properties", PropertiesText(o.tolerance)},
          {"properties_hold", report.violations.empty()},
          {"violations", violations},
          {"cases", cases},
          {"equivalent_snr", report.equivalent ? report.equivalent->to_json() : nlohmann::json(nullptr)}};
}

namespace {

// "lo hi" minus the truth over `scale`, or "NaN NaN" (gnuplot skips undefined values).
std::string PlotPair(double lo, double hi, double truth, double scale) {
  if (!std::isfinite(lo) || !std::isfinite(hi)) return "NaN NaN";
  return fmt::format("{:.6g} {:.6g}", (lo - truth) / scale, (hi - truth) / scale);
}

std::string PlotData(const std::vector<const TableCase*>& group, const std::vector<int>& orders) {
  std::string data = "# x label inner_lo inner_hi paper_lo paper_hi then outer_lo outer_hi per order\n";
  int x = 0;
  for (const auto* c : group)
    for (const auto& inner : c->inner.intervals) {
      const double truth = TruthOf(*c, inner.name);
      const auto paper = PaperTableInterval(inner.name, c->horizon);
      double scale = paper ? paper->half_width() : inner.half_width();
      if (!(scale > 0)) scale = 1.0;
      data += fmt::format("{} {},n={} {} {}", x++, inner.name, c->horizon,
                          inner.found ? PlotPair(inner.lower, inner.upper, truth, scale) : "NaN NaN",
                          paper ? PlotPair(paper->lower, paper->upper, truth, scale) : "NaN NaN");
      for (int order : orders) {
        const auto run = c->outer.find(order);
        const auto* outer = run == c->outer.end() ? nullptr : FindInterval(run->second, inner.name);
        data += " " + (outer ? PlotPair(outer->lower.value, outer->upper.value, truth, scale) : "NaN NaN");
      }
      data += "\n";
    }
  return data;
}

std::string PlotScript(const std::string& stem, const std::string& title, const std::vector<int>& orders) {
  std::string plot = fmt::format(
      "plot '{0}.dat' using ($1-0.3):(($3+$4)/2):3:4:xtic(2) with yerrorbars pt 0 lw 3 lc rgb 'forest-green' "
      "title 'inner hull', '' using ($1-0.1):(($5+$6)/2):5:6 with yerrorbars pt 0 lw 2 lc rgb 'black' title "
      "'paper (delta = 3)'",
      stem);
  const char* colours[] = {"'royalblue'", "'dark-orange'", "'purple'", "'red'"};
  for (std::size_t i = 0; i < orders.size(); ++i)
    plot += fmt::format(", '' using ($1+{0:.2f}):((${1}+${2})/2):{1}:{2} with yerrorbars pt 0 lw 2 lc rgb {3} "
                        "title 'outer, delta = {4}'",
                        0.1 + 0.2 * static_cast<double>(i), 7 + 2 * i, 8 + 2 * i, colours[i % 4], orders[i]);
  return fmt::format(
      "set terminal pngcairo size 1200,650\nset output '{}.png'\nset title '{}'\nset ylabel '(value - truth) / "
      "paper half-width'\nset termoption noenhanced\nset offsets 0.6, 0.6, 0, 0\nset xtics rotate by -45\n"
      "set grid ytics\nset key outside right\nset xzeroaxis lt -1\n{}\n",
      stem, title, plot);
}

}  // namespace

std::vector<PlotFiles> TablesPlots(const TablesReport& report) {
  std::vector<PlotFiles> plots;
  for (const auto& [key, group] : ByRealisation(report.cases)) {
    const std::string stem = fmt::format("intervals_snr{:g}_seed{}", key.first, key.second);
    const std::string title = fmt::format("Paper 001 example, N = {}, SNR {:g} dB, seed {}: intervals minus truth",
                                          group.front()->samples, key.first, key.second);
    plots.push_back({stem, PlotData(group, report.options.orders), PlotScript(stem, title, report.options.orders)});
  }
  return plots;
}

std::vector<std::string> WriteTables(const std::string& dir, const TablesReport& report) {
  std::vector<std::string> messages;
  write_text_atomic(dir + "/tables.md", TablesMarkdown(report));
  write_text_atomic(dir + "/tables.json", TablesJson(report).dump(2) + "\n");
  const bool have_gnuplot = GnuplotAvailable();
  if (!have_gnuplot) messages.push_back("gnuplot not found: the plot data and scripts are in " + dir + " (*.dat, *.gp)");
  for (const auto& plot : TablesPlots(report)) {
    write_text_atomic(dir + "/" + plot.stem + ".dat", plot.data);
    write_text_atomic(dir + "/" + plot.stem + ".gp", plot.script);
    if (!have_gnuplot) continue;
    if (const std::string failed = RunGnuplot(dir, plot.stem + ".gp"); !failed.empty()) messages.push_back(failed);
  }
  messages.push_back(fmt::format("wrote {}/tables.md, tables.json and the plots", dir));
  return messages;
}

}  // namespace hw::cerone
