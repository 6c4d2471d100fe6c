#pragma once
// Polynomial optimisation problems from JSON, for `hwbounds pop`:
// {
//   "variables": ["x1", "x2"],
//   "minimize": "x1^2 + x2",              (or "maximize")
//   "constraints": ["x1^2 + x2^2 <= 1", "x1 - x2 == 0", "x2 >= -1"],
//   "box": {"x1": [-2, 2], "x2": [-2, 2]}   (optional; all variables or none)
// }
// Errors name the file, the field and, inside an expression, the character position; a key other than these
// five is an error (a typo such as "constraint" must not drop the constraints).
#include <string>

#include <nlohmann/json.hpp>

#include "pop/moment_relaxation.hpp"

namespace hw::pop {

PolyProblem ParsePolyProblem(const nlohmann::json& j, const std::string& source);
PolyProblem LoadPolyProblem(const std::string& path);

// An order asked for (the CLI's --order, the Python module's order): at least the problem's minimal order.
// False with the message both report in *error otherwise (leaving the order unset selects the minimal order).
bool ValidRelaxationOrder(const PolyProblem& problem, int order, std::string* error);
// The outcome as `hwbounds pop --json` prints it (and the Python module returns): status, message, order, solver,
// sdp_status, moments, blocks, flat, sense, and when solved bound, first_moments, minimizers, rank.
nlohmann::json RelaxationJson(const PolyProblem& problem, const RelaxationResult& r, const std::string& solver);

}  // namespace hw::pop
