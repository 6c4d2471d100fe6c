// hwbounds.read_recording, hwbounds.simulate, hwbounds.pop.
#include <fmt/format.h>

#include "core/hw_model.hpp"
#include "core/recording.hpp"
#include "pop/pop_json.hpp"
#include "pop/relaxation_size.hpp"
#include "python/py_convert.hpp"
#include "python/py_module.hpp"
#include "sdp/sdp_solver.hpp"

namespace hw::python {

void DefineRecordings(py::module_& m) {
  m.def(
      "read_recording",
      [](const std::string& spec, const std::vector<std::string>& required, const std::vector<std::string>& optional) {
        const CsvTable t = read_recording(spec, required, optional);
        py::dict out;  // the columns asked for, as from a .mat file (a CSV may hold more)
        for (const auto* names : {&required, &optional})
          for (const auto& name : *names)
            if (t.has(name)) out[py::str(name)] = ToArray(t.column(name));
        return out;
      },
      R"doc(Reads a recording as every command does: "rec.csv", "rec.mat:u=vir,y=qm[,t=time]" (MATLAB v4, v5,
v7.3), "rec.mat" (variables named as the columns) or "rec.csv:u=V1,y=V2". required columns must be there,
optional ones may be. Returns {column: numpy array} for those columns. Bad input raises ValueError with
the CLI's message.)doc",
      py::arg("spec"), py::arg("required") = std::vector<std::string>{"u", "y"},
      py::arg("optional") = std::vector<std::string>{"t"});
}

void DefineModels(py::module_& m) {
  m.def(
      "simulate",
      [](py::handle model, py::handle u, bool allow_unstable) {
        const std::string source = py::isinstance<py::str>(model) ? model.cast<std::string>() : "model";
        const HwModel hw = py::isinstance<py::str>(model) ? HwModel::load(source) : HwModel::from_json(ToJson(model));
        CheckStableOrAllowed(hw, source, allow_unstable);  // the CLI's checks (cli/cmd_simulate.cpp)
        const auto input = ToVector(u, "u");
        const auto w = WithoutGil([&] { return hw.simulate(input); });
        CheckFiniteOutput(w, source, [](std::size_t t) { return fmt::format("u[{}]", t); });
        return ToArray(w);
      },
      R"doc(Noise-free output w of a model (a dict in the Model JSON format of docs/input_output.md, or the path of such a
file) driven by the input u, simulated from rest as `hwbounds simulate` does. A model whose linear block is
unstable is refused unless allow_unstable (the CLI's --allow-unstable), and an output that overflows double
precision is an error, both with the CLI's message. Returns a numpy array.)doc",
      py::arg("model"), py::arg("u"), py::kw_only(), py::arg("allow_unstable") = false);

  const pop::RelaxationOptions r;
  m.def(
      "pop",
      [](py::handle problem, py::object order, const std::string& solver, double rank_tolerance,
         double extraction_tolerance) {
        const pop::PolyProblem p = py::isinstance<py::str>(problem)
                                         ? pop::LoadPolyProblem(problem.cast<std::string>())
                                         : pop::ParsePolyProblem(ToJson(problem), "problem");
        // The CLI's checks of --order and --solver (cli/cmd_pop.cpp), in its order.
        const bool order_given = !order.is_none();
        if (order_given) Require([&](std::string* e) { return pop::ValidRelaxationOrder(p, order.cast<int>(), e); });
        Require([&](std::string* e) { return sdp::ValidSolverName(solver, e); });
        pop::RelaxationOptions options;
        options.order = order_given ? order.cast<int>() : 0;  // 0: the minimal order
        options.rank_tolerance = rank_tolerance;
        options.extraction_tolerance = extraction_tolerance;
        RequireValid(options);
        const int solve_order = order_given ? options.order : p.minimal_order();
        Require([&](std::string* e) { return pop::RelaxationFits(p, solve_order, solver, e); });
        auto backend = sdp::MakeSolver(solver);
        const auto result = WithoutGil([&] { return pop::SolveRelaxation(options, p, *backend); });
        return ToPython(pop::RelaxationJson(p, result, solver));
      },
      R"doc(One moment (Lasserre) relaxation of a polynomial optimisation problem, as `hwbounds pop --json`.
problem: a dict {"variables": [...], "minimize" | "maximize": "...", "constraints": [...], "box": {...}} or the
path of such a JSON file; order None = the problem's minimal order (as the CLI without --order); an order
below it, an unknown solver, or a relaxation larger than the memory available raise ValueError with the
CLI's message. Returns the CLI's JSON as a dict (status, bound when solved, flat, minimizers, ...).)doc",
      py::arg("problem"), py::arg("order") = py::none(), py::arg("solver") = "sdpa", py::kw_only(),
      py::arg("rank_tolerance") = r.rank_tolerance, py::arg("extraction_tolerance") = r.extraction_tolerance);
}

}  // namespace hw::python
