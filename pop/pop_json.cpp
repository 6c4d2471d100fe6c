#include "pop/pop_json.hpp"

#include <algorithm>
#include <cctype>

#include <fmt/format.h>

#include "core/csv_table.hpp"
#include "core/json_input.hpp"

namespace hw::pop {
namespace {

Polynomial parse_field(const std::string& text, const std::vector<std::string>& names, const std::string& where) {
  try {
    return parse_polynomial(text, names);
  } catch (const PolynomialParseError& e) {
    throw InputError(fmt::format("{}: \"{}\" {}", where, text, e.what()));
  }
}

bool is_identifier(const std::string& s) {
  if (s.empty() || !(std::isalpha(static_cast<unsigned char>(s[0])) || s[0] == '_')) return false;
  for (char c : s)
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_')) return false;
  return true;
}

std::vector<std::string> ReadVariables(const nlohmann::json& j, const std::string& source) {
  if (!j.contains("variables") || !j["variables"].is_array() || j["variables"].empty())
    throw InputError(fmt::format("{}: \"variables\" must be a non-empty list of names, e.g. [\"x1\", \"x2\"]", source));
  std::vector<std::string> names;
  for (const auto& v : j["variables"]) {
    if (!v.is_string() || !is_identifier(v.get<std::string>()))
      throw InputError(fmt::format("{}: variables: {} is not a name (letters, digits and '_', not starting with a digit)",
                                   source, v.dump()));
    const auto name = v.get<std::string>();
    if (std::find(names.begin(), names.end(), name) != names.end())
      throw InputError(fmt::format("{}: variables: '{}' is listed twice", source, name));
    names.push_back(name);
  }
  return names;
}

// "lhs >= rhs", "lhs <= rhs" or "lhs == rhs" as g >= 0 (inequality) or h = 0 (equality).
void ReadConstraint(const std::string& text, const std::string& where, PolyProblem* p) {
  std::size_t at;
  if ((at = text.find(">=")) != std::string::npos) {
    p->inequalities.push_back(parse_field(text.substr(0, at), p->names, where) -
                              parse_field(text.substr(at + 2), p->names, where));
  } else if ((at = text.find("<=")) != std::string::npos) {
    p->inequalities.push_back(parse_field(text.substr(at + 2), p->names, where) -
                              parse_field(text.substr(0, at), p->names, where));
  } else if ((at = text.find("==")) != std::string::npos) {
    p->equalities.push_back(parse_field(text.substr(0, at), p->names, where) -
                            parse_field(text.substr(at + 2), p->names, where));
  } else {
    throw InputError(where + ": \"" + text + "\" has no relation; use >=, <= or ==");
  }
}

void ReadBox(const nlohmann::json& b, const std::string& source, PolyProblem* p) {
  if (!b.is_object()) throw InputError(fmt::format("{}: \"box\" must map every variable to [lo, hi]", source));
  for (const auto& [key, value] : b.items())
    if (std::find(p->names.begin(), p->names.end(), key) == p->names.end())
      throw InputError(fmt::format("{}: box: '{}' is not a variable; the variables are: {}", source, key,
                                   fmt::join(p->names, ", ")));
  for (const auto& name : p->names) {
    if (!b.contains(name) || !b[name].is_array() || b[name].size() != 2 || !b[name][0].is_number() ||
        !b[name][1].is_number())
      throw InputError(fmt::format("{}: box: variable '{}' needs [lo, hi] (two numbers)", source, name));
    p->box.push_back({b[name][0].get<double>(), b[name][1].get<double>()});
  }
}

}  // namespace

PolyProblem ParsePolyProblem(const nlohmann::json& j, const std::string& source) {
  PolyProblem p;
  if (!j.is_object()) throw InputError(fmt::format("{}: expected a JSON object with variables, minimize/maximize, constraints", source));
  CheckKeys(j, {"variables", "minimize", "maximize", "constraints", "box"}, source);
  p.names = ReadVariables(j, source);
  p.num_vars = static_cast<int>(p.names.size());
  const bool has_min = j.contains("minimize"), has_max = j.contains("maximize");
  if (has_min == has_max)
    throw InputError(fmt::format("{}: give exactly one of \"minimize\" or \"maximize\" (an expression string)", source));
  const std::string key = has_min ? "minimize" : "maximize";
  if (!j[key].is_string()) throw InputError(fmt::format("{}: \"{}\" must be an expression string", source, key));
  p.objective = parse_field(j[key].get<std::string>(), p.names, fmt::format("{}: {}", source, key));
  p.maximize = has_max;
  if (j.contains("constraints")) {
    if (!j["constraints"].is_array()) throw InputError(fmt::format("{}: \"constraints\" must be a list of strings", source));
    int i = 0;
    for (const auto& c : j["constraints"]) {
      const std::string where = fmt::format("{}: constraints[{}]", source, i++);
      if (!c.is_string()) throw InputError(where + ": expected a string such as \"x1^2 + x2^2 <= 1\"");
      ReadConstraint(c.get<std::string>(), where, &p);
    }
  }
  if (j.contains("box")) ReadBox(j["box"], source, &p);
  std::string error;
  if (!p.IsValid(&error)) throw InputError(fmt::format("{}: {}", source, error));
  return p;
}

PolyProblem LoadPolyProblem(const std::string& path) { return ParsePolyProblem(ReadJsonFile(path, "problem JSON file"), path); }

bool ValidRelaxationOrder(const PolyProblem& problem, int order, std::string* error) {
  if (order >= problem.minimal_order()) return true;
  if (error)
    *error = fmt::format("order {} is below this problem's minimal order {}; leave the order unset for the minimal "
                         "order",
                         order, problem.minimal_order());
  return false;
}

nlohmann::json RelaxationJson(const PolyProblem& problem, const RelaxationResult& r, const std::string& solver) {
  nlohmann::json j = {{"status", ToString(r.status)}, {"message", r.message}, {"order", r.order},
                      {"solver", solver}, {"sdp_status", sdp::ToString(r.sdp.status)},
                      {"moments", r.num_moments}, {"blocks", r.num_blocks}, {"flat", r.flat},
                      {"sense", problem.maximize ? "max" : "min"}};
  if (r.status == RelaxationStatus::kSolved) {
    j["bound"] = r.bound;
    j["first_moments"] = r.first_moments;
    j["minimizers"] = r.minimizers;
    j["rank"] = r.rank;
  }
  return j;
}

}  // namespace hw::pop
