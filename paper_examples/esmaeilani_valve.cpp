// Reproduction of paper 002 (Esmaeilani et al., IET CTA 2020), Section 4: the pressure-control valve,
// rebuilt in simulation (the plant recordings are private). Twelve closing operations: nine for
// estimation, three for validation. Writes Markdown + JSON + CSV + gnuplot PNGs to the output dir.
// Reports two estimates from the same data: the paper's SQP alone, and the SQP followed by the
// output-error refinement (RefineOutputError, an addition to the paper) started from it.
//   esmaeilani_valve [out_dir] [samples_per_operation] [w_state w_output w_noise] [max_iterations]
//                    [oe_max_iterations] [steady|estimate  (initial states of the output-error refinement; default steady)]
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <string>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "core/atomic_write.hpp"
#include "core/csv_table.hpp"
#include "core/hw_model.hpp"
#include "estimators/esmaeilani/estimator.hpp"
#include "estimators/esmaeilani/valve_case.hpp"

using namespace hw;
using namespace hw::esmaeilani;

namespace {

double MaxAbsError(const std::vector<double>& y, const std::vector<double>& yh) {
  double m = 0.0;
  for (std::size_t i = 0; i < y.size(); ++i) m = std::max(m, std::abs(y[i] - yh[i]));
  return m;
}

}  // namespace

int main(int argc, char** argv) {
  const std::string out = argc > 1 ? argv[1] : "esmaeilani_valve_out";
  const int samples = argc > 2 ? std::atoi(argv[2]) : 150;
  std::filesystem::create_directories(out);
  ValveCase valve;
  std::vector<Segment> est, val;
  std::vector<std::vector<double>> val_w;
  for (unsigned k = 0; k < 12; ++k) {
    std::vector<double> w;
    Segment s = valve.ClosingOperation(1000 + k, samples, &w);
    if (k < 9) {
      est.push_back(s);
    } else {
      val.push_back(s);
      val_w.push_back(w);
    }
  }
  Options opt;
  opt.order = 3;
  opt.grid_f = 12;
  opt.grid_g = 12;
  // Residual weights (state, output, noise): the paper's are 1, 1, 1.
  if (argc > 3) opt.weight_state = std::atof(argv[3]);
  if (argc > 4) opt.weight_output = std::atof(argv[4]);
  if (argc > 5) opt.weight_noise = std::atof(argv[5]);
  if (argc > 6) opt.max_iterations = std::atoi(argv[6]);
  if (argc > 7) opt.oe_max_iterations = std::atoi(argv[7]);
  // "steady": each operation starts at the model's steady state at its first command (known here: every
  // closing operation starts fully open at rest); "estimate": initial states are unknowns of the refinement.
  if (argc > 8) opt.oe_estimate_initial_states = std::string(argv[8]) == "estimate";
  // The true system in the estimator's normalisation f(0)=0, f(50)=50, g^{-1}(20)=20, g^{-1}(80)=80.
  EsmaeilaniModel truth = valve.TrueModel(41);
  {
    const double c = 60.0 / (valve.g_inverse(80) - valve.g_inverse(20)), o = 20.0 - c * valve.g_inverse(20);
    for (auto& v : truth.ginv_values) v = c * v + o;
    for (auto& v : truth.b) v *= c;
    truth.output_offset = o;
  }
  if (std::getenv("ESM_START_AT_TRUTH")) opt.initial = &truth;  // diagnostic: warm start at the truth
  const Constraints cons = valve.KnownInformation();
  // The same data and known information as files, for `hwbounds esmaeilani` (see docs/esmaeilani.md).
  for (std::size_t k = 0; k < 12; ++k) {
    const Segment& s = k < 9 ? est[k] : val[k - 9];
    CsvTable t;
    t.add_column("u", s.u);
    t.add_column("y", s.y);
    write_csv(fmt::format("{}/{}{}.csv", out, k < 9 ? "est" : "val", k < 9 ? k + 1 : k - 8), t);
  }
  write_text_atomic(out + "/valve_constraints.json", cons.ToJson().dump(2) + "\n");
  Summary sum;
  const EsmaeilaniModel m = Estimate(opt, est, cons, &sum);
  fmt::print("{}: {} iterations, cost {:.4g} -> {:.4g}, {:.2f} s (QP {:.2f} s, {} Ipopt iterations), {} unknowns\n",
             sum.message, sum.iterations, sum.initial_cost, sum.final_cost, sum.seconds, sum.qp_seconds,
             sum.qp_iterations, sum.unknowns);
  fmt::print("cost history: {:.4g}\n", fmt::join(sum.cost_history, " "));
  fmt::print("steps: {:.3g}\n", fmt::join(sum.step_lengths, " "));
  fmt::print("a = [{:.4f}], b = [{:.4f}], d = {:.4f}\n", fmt::join(m.a, ", "), fmt::join(m.b, ", "), m.d);
  fmt::print("f' = [{:.2f}]\n", fmt::join(m.f_values, ", "));
  fmt::print("g^-1' = [{:.2f}] on y' = [{:.1f}]\n", fmt::join(m.ginv_values, ", "), fmt::join(m.y_grid, ", "));
  // Output-error refinement from the SQP estimate (estimation data only).
  OutputErrorSummary oes;
  const EsmaeilaniModel mo = RefineOutputError(opt, est, cons, m, &oes);
  fmt::print("output-error refinement: {}; {} iterations, simulation error {:.4g} -> {:.4g}, {:.2f} s (QP {:.2f} s), "
             "{} parameters, max constraint violation {:.2g}\n", oes.message, oes.iterations, oes.initial_cost,
             oes.final_cost, oes.seconds, oes.qp_seconds, oes.parameters, oes.max_constraint_violation);
  fmt::print("output-error cost history: {:.4g}\n", fmt::join(oes.cost_history, " "));
  double truth_oe_cost = 0.0;
  {  // the true system's simulation error on the same estimation data, from the steady state (reference)
    double& c = truth_oe_cost;
    for (const auto& s : est) {
      const auto yh = truth.Simulate(s.u);
      for (std::size_t t = 0; t < yh.size(); ++t) c += (s.y[t] - yh[t]) * (s.y[t] - yh[t]);
    }
    fmt::print("true system's simulation error on the estimation data: {:.4g}\n", c);
  }
  fmt::print("refined a = [{:.4f}], b = [{:.4f}]\n", fmt::join(mo.a, ", "), fmt::join(mo.b, ", "));
  fmt::print("refined f' = [{:.2f}]\n", fmt::join(mo.f_values, ", "));
  fmt::print("refined g^-1' = [{:.2f}]\n", fmt::join(mo.ginv_values, ", "));
  nlohmann::json report = {{"case", "valve (simulated rebuild of paper 002 Section 4)"},
                           {"samples_per_operation", samples},
                           {"estimation_operations", est.size()},
                           {"validation_operations", val.size()},
                           {"order", opt.order},
                           {"grid_f", opt.grid_f},
                           {"grid_g", opt.grid_g},
                           {"weights", {opt.weight_state, opt.weight_output, opt.weight_noise}},
                           {"status", sum.message},
                           {"iterations", sum.iterations},
                           {"unknowns", sum.unknowns},
                           {"seconds", sum.seconds},
                           {"qp_seconds", sum.qp_seconds},
                           {"final_cost", sum.final_cost},
                           {"estimate", m.ToJson()},
                           {"output_error", {{"status", oes.message}, {"iterations", oes.iterations},
                                             {"seconds", oes.seconds}, {"qp_seconds", oes.qp_seconds},
                                             {"parameters", oes.parameters}, {"initial_cost", oes.initial_cost},
                                             {"final_cost", oes.final_cost},
                                             {"true_system_cost", truth_oe_cost},
                                             {"max_constraint_violation", oes.max_constraint_violation},
                                             {"estimate", mo.ToJson()}}},
                           {"truth_normalised", truth.ToJson()}};
  std::string md = "# Esmaeilani valve case (simulated rebuild of paper 002, Section 4)\n\n";
  md += fmt::format("Nine closing operations for estimation, three for validation, {} samples each; order {}, "
                    "{} + {} ordered pairs, weights (state, output, noise) = ({}, {}, {}).\n\n",
                    samples, opt.order, opt.grid_f, opt.grid_g, opt.weight_state, opt.weight_output,
                    opt.weight_noise);
  md += fmt::format("Solver: {} after {} SQP iterations, {:.2f} s ({:.2f} s in Ipopt QPs), {} unknowns.\n\n",
                    sum.message, sum.iterations, sum.seconds, sum.qp_seconds, sum.unknowns);
  md += fmt::format("Estimated a = [{:.4f}], b = [{:.4f}] (paper order; truth in this normalisation: a = [{:.4f}], "
                    "b = [{:.4f}])\n\n", fmt::join(m.a, ", "), fmt::join(m.b, ", "), fmt::join(truth.a, ", "),
                    fmt::join(truth.b, ", "));
  md += fmt::format("Output-error refinement: {} after {} iterations, {:.2f} s ({:.2f} s in Ipopt QPs), {} parameters, "
                    "simulation error on the estimation data {:.4g} -> {:.4g}.\n\n", oes.message, oes.iterations,
                    oes.seconds, oes.qp_seconds, oes.parameters, oes.initial_cost, oes.final_cost);
  md += "| operation | estimate | fit % = 100(1-‖y-ŷ‖/‖y-ȳ‖) | max error (% of range 0-100) | fit vs noise-free % |\n"
        "|---|---|---|---|---|\n";
  CsvTable traces;
  for (std::size_t k = 0; k < val.size(); ++k) {
    traces.add_column(fmt::format("u{}", k + 1), val[k].u);
    traces.add_column(fmt::format("y{}", k + 1), val[k].y);
    for (int variant = 0; variant < 3; ++variant) {
      const EsmaeilaniModel& mm = variant == 0 ? m : variant == 1 ? mo : truth;
      const char* name = variant == 0 ? "SQP (paper)" : variant == 1 ? "SQP + output error" : "true system";
      const auto yh = mm.Simulate(val[k].u);
      const double fit = fit_percent(val[k].y, yh), fitw = fit_percent(val_w[k], yh);
      const double maxe = MaxAbsError(val[k].y, yh);
      fmt::print("validation {} {}: fit {:.2f} %, max error {:.2f} %, fit vs noise-free {:.2f} %\n", k + 1, name, fit,
                 maxe, fitw);
      md += fmt::format("| {} | {} | {:.2f} | {:.2f} | {:.2f} |\n", k + 1, name, fit, maxe, fitw);
      report[variant == 0 ? "validation" : variant == 1 ? "validation_output_error" : "validation_true_system"]
          .push_back({{"fit_percent", fit}, {"max_error_percent_of_range", maxe}, {"fit_noise_free", fitw}});
      if (variant < 2) traces.add_column(fmt::format("yhat{}{}", variant == 0 ? "" : "oe", k + 1), yh);
    }
  }
  write_csv(out + "/validation.csv", traces);
  CsvTable fcurve, gcurve;
  std::vector<double> uu, ft, fe, fo, yy, gt, ge, go;
  for (int i = 0; i <= 200; ++i) {
    const double u = 0.5 * i;
    uu.push_back(u), ft.push_back(truth.F(u)), fe.push_back(m.F(u)), fo.push_back(mo.F(u));
    const double y = m.y_grid.front() + (m.y_grid.back() - m.y_grid.front()) * i / 200.0;
    yy.push_back(y), gt.push_back(truth.Ginv(y)), ge.push_back(m.Ginv(y)), go.push_back(mo.Ginv(y));
  }
  fcurve.add_column("u", uu), fcurve.add_column("f_true", ft), fcurve.add_column("f_sqp", fe);
  fcurve.add_column("f_sqp_oe", fo);
  gcurve.add_column("y", yy), gcurve.add_column("ginv_true", gt), gcurve.add_column("ginv_sqp", ge);
  gcurve.add_column("ginv_sqp_oe", go);
  write_csv(out + "/f_curve.csv", fcurve);
  write_csv(out + "/ginv_curve.csv", gcurve);
  const std::string gp = R"(set terminal pngcairo size 1200,450
set datafile separator ','
set key autotitle columnhead
set output 'functions.png'
set multiplot layout 1,2
set title 'Hammerstein function f (normalised f(0)=0, f(50)=50)'
set xlabel 'command u (%)'
plot 'f_curve.csv' u 1:2 w l lw 2 t 'true', '' u 1:3 w l lw 2 dt 2 t 'SQP (paper)', '' u 1:4 w l lw 2 dt 3 t 'SQP + output error'
set title 'inverse Wiener function g^{-1} (normalised g^{-1}(20)=20, g^{-1}(80)=80)'
set xlabel 'valve position y (%)'
plot 'ginv_curve.csv' u 1:2 w l lw 2 t 'true', '' u 1:3 w l lw 2 dt 2 t 'SQP (paper)', '' u 1:4 w l lw 2 dt 3 t 'SQP + output error'
unset multiplot
set output 'validation.png'
set multiplot layout 1,3
set xlabel 'sample'
set yrange [-5:105]
do for [k=1:3] {
  set title sprintf('validation operation %d', k)
  plot 'validation.csv' u 0:(column(4*k-3)) w l t 'command u', '' u 0:(column(4*k-2)) w l t 'measured y', '' u 0:(column(4*k-1)) w l dt 2 lw 2 t 'SQP (paper)', '' u 0:(column(4*k)) w l dt 3 lw 2 t 'SQP + output error'
}
unset multiplot
)";
  write_text_atomic(out + "/plots.gp", gp);
  md += "\n![functions](functions.png)\n\n![validation](validation.png)\n";
  write_text_atomic(out + "/report.md", md);
  write_text_atomic(out + "/report.json", report.dump(2) + "\n");
  const int rc = std::system(fmt::format("cd '{}' && gnuplot plots.gp", out).c_str());
  if (rc != 0) fmt::print(stderr, "gnuplot failed (exit {}); data and script are in {}\n", rc, out);
  return 0;
}
