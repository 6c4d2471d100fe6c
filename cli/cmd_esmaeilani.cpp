// `hwbounds esmaeilani`: Esmaeilani et al. (2020) constrained least-squares HW estimator on one or more
// recorded segments (each with its own initial condition); writes the project model JSON.
#include <algorithm>
#include <cmath>
#include <filesystem>

#include <fmt/format.h>

#include "cli/commands.hpp"
#include "core/atomic_write.hpp"
#include "core/csv_table.hpp"
#include "core/hw_model.hpp"
#include "core/output_files.hpp"
#include "core/recording.hpp"
#include "estimators/esmaeilani/estimator.hpp"

namespace hw::cli {

void AddEsmaeilaniCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "esmaeilani",
      "Esmaeilani et al. 2020: HW model with ordered-pair nonlinearities from several recorded segments "
      "(constrained least squares, Gauss-Newton SQP); writes a model JSON usable by `simulate`");
  struct Opts {
    std::vector<std::string> data, validate;
    std::string constraints, out = "esmaeilani_model.json", u_col = "u", y_col = "y";
    int order = 3, grid_f = 12, grid_g = 12, max_iterations = 100, oe_max_iterations = 100;
    double weight_state = 1.0, weight_output = 1.0, weight_noise = 1.0;
    bool no_clamp = false, refine_oe = false, oe_estimate_x0 = false;
  };
  auto o = std::make_shared<Opts>();
  cmd->add_option("--data", o->data,
                  "segments used for estimation (CSV with columns u,y, or FILE.mat:u=VAR,y=VAR[,t=VAR]; one segment per file)")
      ->required()
      ->expected(1, -1);
  cmd->add_option("--order", o->order, "order n of the linear block (observable canonical form)");
  cmd->add_option("--grid-f", o->grid_f, "number of ordered pairs of f (input grid u')");
  cmd->add_option("--grid-g", o->grid_g, "number of ordered pairs of g^-1 (output grid y')");
  cmd->add_option("--constraints", o->constraints,
                  "known information JSON: {\"f\":{\"range\":[lo,hi],\"slopes\":[{\"from\":..,\"to\":..,\"min\":..,"
                  "\"max\":..}],\"points\":[[at,value],[at,lo,hi]]},\"g_inverse\":{...},\"d\":0}");
  cmd->add_option("--validate", o->validate, "CSV segments not used for estimation: report fit and max error")
      ->expected(1, -1);
  cmd->add_option("--u-col", o->u_col, "input column name");
  cmd->add_option("--y-col", o->y_col, "output column name");
  cmd->add_option("--max-iterations", o->max_iterations, "SQP iteration limit");
  cmd->add_option("--weight-state", o->weight_state, "weight of the state-equation residual mu (paper: 1)");
  cmd->add_option("--weight-output", o->weight_output, "weight of the output-equation residual e (paper: 1)");
  cmd->add_option("--weight-noise", o->weight_noise, "weight of the input-noise term v = eta + eps_f (paper: 1)");
  cmd->add_flag("--no-clamp", o->no_clamp, "extrapolate g linearly instead of holding it outside the identified range");
  cmd->add_flag("--refine-oe", o->refine_oe,
                "after the paper's SQP, minimise the simulation (output) error of the estimation segments under the "
                "same constraints (Levenberg-Marquardt, one QP per step; not in the paper)");
  cmd->add_option("--oe-max-iterations", o->oe_max_iterations, "iteration limit of the output-error refinement");
  cmd->add_flag("--oe-estimate-initial-states", o->oe_estimate_x0,
                "output-error refinement: estimate each segment's initial state instead of starting it at the model's "
                "steady state at its first input (the default, as in the validation)");
  cmd->add_option("--out", o->out, "model JSON to write");
  cmd->callback([o] {
    auto load = [&](const std::string& path) {
      // A time column (t=VAR, or a CSV column t) is checked and not used: the estimator runs on the sample index.
      const CsvTable t = read_recording(path, {o->u_col, o->y_col}, {"t"});
      esmaeilani::Segment s;
      s.u = t.column(o->u_col);
      s.y = t.column(o->y_col);
      s.name = path;
      return s;
    };
    CheckOutputFile(o->out, "--out");
    std::vector<esmaeilani::Segment> segs, validation;  // every input is read before any work
    for (const auto& p : o->data) segs.push_back(load(p));
    for (const auto& p : o->validate) validation.push_back(load(p));
    esmaeilani::Constraints cons;
    if (!o->constraints.empty()) cons = esmaeilani::Constraints::Load(o->constraints);
    esmaeilani::Options opt;
    opt.order = o->order;
    opt.grid_f = o->grid_f;
    opt.grid_g = o->grid_g;
    opt.max_iterations = o->max_iterations;
    opt.weight_state = o->weight_state;
    opt.weight_output = o->weight_output;
    opt.weight_noise = o->weight_noise;
    opt.clamp_output = !o->no_clamp;
    opt.refine_output_error = o->refine_oe;
    opt.oe_max_iterations = o->oe_max_iterations;
    opt.oe_estimate_initial_states = o->oe_estimate_x0;
    std::string err;
    if (!opt.IsValid(&err)) throw InputError(err);
    esmaeilani::Summary sum;
    const auto m = esmaeilani::Estimate(opt, segs, cons, &sum);
    if (!sum.ok()) throw std::runtime_error("esmaeilani: estimation failed: " + sum.message);
    fmt::print("{} ({} iterations, cost {:.6g} -> {:.6g}, {:.2f} s of which QP {:.2f} s; {} unknowns, {} equations, "
               "{} constraints)\n", sum.message, sum.iterations, sum.initial_cost, sum.final_cost, sum.seconds,
               sum.qp_seconds, sum.unknowns, sum.equations, sum.constraints);
    if (sum.output_error.ran)
      fmt::print("output-error refinement: {} ({} iterations, simulation error {:.6g} -> {:.6g}, {:.2f} s of which QP "
                 "{:.2f} s; {} parameters, max constraint violation {:.2g})\n", sum.output_error.message,
                 sum.output_error.iterations, sum.output_error.initial_cost, sum.output_error.final_cost,
                 sum.output_error.seconds, sum.output_error.qp_seconds, sum.output_error.parameters,
                 sum.output_error.max_constraint_violation);
    fmt::print("paper parametrisation: a = [{:.6g}], b = [{:.6g}], d = {:.6g}, m_e = {:.6g}\n", fmt::join(m.a, ", "),
               fmt::join(m.b, ", "), m.d, m.output_offset);
    fmt::print("f pairs (u', f'):\n");
    for (std::size_t k = 0; k < m.u_grid.size(); ++k) fmt::print("  {:12.6g} {:12.6g}\n", m.u_grid[k], m.f_values[k]);
    fmt::print("g^-1 pairs (y', g'):\n");
    for (std::size_t k = 0; k < m.y_grid.size(); ++k)
      fmt::print("  {:12.6g} {:12.6g}\n", m.y_grid[k], m.ginv_values[k]);
    const HwModel model = m.ToHwModel(opt.clamp_output);
    const nlohmann::json j = esmaeilani::ModelFileJson(m, opt, cons, sum);
    for (const auto& seg : validation) {
      const auto yh = m.Simulate(seg.u, {}, opt.clamp_output);
      double maxe = 0.0;
      for (std::size_t i = 0; i < yh.size(); ++i) maxe = std::max(maxe, std::abs(seg.y[i] - yh[i]));
      const auto [lo, hi] = std::minmax_element(seg.y.begin(), seg.y.end());
      fmt::print("validate {}: fit {:.2f} % (100(1-|y-yhat|/|y-mean y|)), RMSE {:.6g}, max error {:.6g} "
                 "({:.2f} % of the output range); simulated from the steady state at the first input\n",
                 seg.name, fit_percent(seg.y, yh), rmse(seg.y, yh), maxe, 100.0 * maxe / std::max(*hi - *lo, 1e-300));
    }
    write_text_atomic(o->out, j.dump(2) + "\n");
    fmt::print("project model: a = [{:.6g}], b = [{:.6g}], delay {}; wrote {}\n", fmt::join(model.linear.a, ", "),
               fmt::join(model.linear.b, ", "), model.linear.delay, o->out);
  });
}

}  // namespace hw::cli
