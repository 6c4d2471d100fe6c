// `hwbounds pop`: one moment relaxation of a polynomial optimisation problem given as JSON.
#include <fmt/format.h>
#include <fmt/ranges.h>

#include "cli/commands.hpp"
#include "core/csv_table.hpp"
#include "core/output_files.hpp"
#include "pop/pop_json.hpp"
#include "pop/relaxation_size.hpp"
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
  cmd->add_option("PROBLEM", o->problem, "problem JSON (see docs/pop.md)")->required();
  // --order and --solver are checked in the callback by the library's checks (the Python module's messages).
  auto* order = cmd->add_option("--order", o->order, "relaxation order delta, at least the problem's minimal order")
                    ->default_str("minimal");
  cmd->add_option("--solver", o->solver, fmt::format("SDP backend: {}", fmt::join(sdp::AvailableSolvers(), ", ")));
  cmd->add_option("--export", o->export_path, "also write the SDP in SDPA sparse format (.dat-s)");
  cmd->add_flag("--json", o->json, "machine-readable output");
  cmd->callback([o, order] {
    if (!o->export_path.empty()) CheckOutputFile(o->export_path, "--export");
    const auto problem = pop::LoadPolyProblem(o->problem);
    const bool order_given = order->count() > 0;
    if (order_given)
      RequireOption("--order", [&](std::string* e) { return pop::ValidRelaxationOrder(problem, o->order, e); });
    RequireOption("--solver", [&](std::string* e) { return sdp::ValidSolverName(o->solver, e); });
    pop::RelaxationOptions options;
    options.order = order_given ? o->order : 0;  // 0: the minimal order
    const int solve_order = order_given ? o->order : problem.minimal_order();
    // Refused, with the numbers, when larger than the memory available now; a large one that fits is announced.
    RequireOption("--order", [&](std::string* e) { return pop::RelaxationFits(problem, solve_order, o->solver, e); });
    const auto size = pop::EstimateRelaxationSize(problem, solve_order, o->solver);
    if (size.bytes > 1e8) fmt::print(stderr, "order {} relaxation: {}\n", solve_order, size.describe());
    auto solver = sdp::MakeSolver(o->solver);
    const auto r = pop::SolveRelaxation(options, problem, *solver);
    const bool failed = r.status == pop::RelaxationStatus::kSolverFailed || r.status == pop::RelaxationStatus::kInvalid;
    if (!o->export_path.empty() && !failed) {  // a result file: written only when the command succeeds
      const pop::MomentRelaxation relaxation(problem, r.order);
      sdp::WriteSdpaSparse(o->export_path, relaxation.lmi());
    }
    const auto names = problem.names.empty() ? default_variable_names(problem.num_vars) : problem.names;
    if (o->json) {
      nlohmann::json j = pop::RelaxationJson(problem, r, o->solver);
      if (!o->export_path.empty() && !failed) j["exported"] = o->export_path;
      fmt::print("{}\n", j.dump(2));
    } else {
      fmt::print("order {} relaxation ({} moments, {} blocks), solver {}: {}\n", r.order, r.num_moments, r.num_blocks,
                 o->solver, pop::ToString(r.status));
      if (r.status == pop::RelaxationStatus::kSolved) {
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
      if (!o->export_path.empty() && !failed) fmt::print("wrote {}\n", o->export_path);
    }
    if (failed) throw std::runtime_error("no valid bound: " + r.message + (o->export_path.empty() ? "" : "; nothing exported"));
  });
}

}  // namespace hw::cli
