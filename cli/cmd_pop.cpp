// `hwbounds pop`: one moment relaxation of a polynomial optimisation problem given as JSON.
#include <fmt/format.h>

#include "cli/commands.hpp"
#include "core/csv_table.hpp"
#include "relax/pop_json.hpp"
#include "sdp/sdp_solver.hpp"
#include "sdp/sdpa_format.hpp"

namespace hw::cli {

void AddPopCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand("pop", "Moment (Lasserre) relaxation of a polynomial optimisation problem (JSON)");
  struct Opts {
    std::string problem, solver = "sdpa", export_path;
    int order = 0;
    bool json = false;
  };
  auto o = std::make_shared<Opts>();
  cmd->add_option("PROBLEM", o->problem, "problem JSON (see README: Polynomial problems)")->required();
  cmd->add_option("--order", o->order, "relaxation order delta (default: minimal)");
  cmd->add_option("--solver", o->solver, "SDP backend")->check(CLI::IsMember(sdp::AvailableSolvers()));
  cmd->add_option("--export", o->export_path, "also write the SDP in SDPA sparse format (.dat-s)");
  cmd->add_flag("--json", o->json, "machine-readable output");
  cmd->callback([o] {
    const auto problem = relax::LoadPolyProblem(o->problem);
    relax::RelaxationOptions options;
    options.order = o->order;
    relax::CheckRelaxationOrder(problem, o->order);
    if (!o->export_path.empty()) {
      const relax::MomentRelaxation relaxation(problem, o->order > 0 ? o->order : problem.minimal_order());
      sdp::WriteSdpaSparse(o->export_path, relaxation.lmi());
    }
    auto solver = sdp::MakeSolver(o->solver);
    const auto r = relax::SolveRelaxation(options, problem, *solver);
    const auto names = problem.names.empty() ? default_variable_names(problem.num_vars) : problem.names;
    if (o->json) {
      nlohmann::json j = relax::RelaxationJson(problem, r, o->solver);
      if (!o->export_path.empty()) j["exported"] = o->export_path;
      fmt::print("{}\n", j.dump(2));
    } else {
      fmt::print("order {} relaxation ({} moments, {} blocks), solver {}: {}\n", r.order, r.num_moments, r.num_blocks,
                 o->solver, relax::ToString(r.status));
      if (r.status == relax::RelaxationStatus::kSolved) {
        fmt::print("{} bound: {:.10g}\n", problem.maximize ? "upper" : "lower", r.bound);
        fmt::print("{}\n", r.message);
        for (const auto& x : r.minimizers) {
          fmt::print("  {}:", problem.maximize ? "maximizer" : "minimizer");
          for (std::size_t i = 0; i < x.size(); ++i) fmt::print(" {}={:.8g}", names[i], x[i]);
          fmt::print("\n");
        }
      } else {
        fmt::print("{}\n", r.message);
      }
      if (!o->export_path.empty()) fmt::print("wrote {}\n", o->export_path);
    }
    if (r.status == relax::RelaxationStatus::kSolverFailed || r.status == relax::RelaxationStatus::kInvalid)
      throw std::runtime_error("no valid bound: " + r.message);
  });
}

}  // namespace hw::cli
