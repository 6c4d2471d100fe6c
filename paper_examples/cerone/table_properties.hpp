#pragma once
// The properties every table must have (paper 001, Section V), checked on the computed cases:
//   truth:   the true parameters lie inside every outer interval (Property 2);
//   order:   the order delta' > delta interval lies inside the order delta one (Property 3; same n and data);
//   horizon: the n' > n interval lies inside the n one (Property 4; same order and data, D^ss(n') ⊆ D^ss(n));
//   witness: every inner witness of D^ss(n') lies inside every outer interval of D^ss(n), n <= n' (same data).
// Containment allows `tolerance` * max(1, |value|): verified endpoints are rounded outward, and a relaxation's
// constraints are scaled and normalised copies of the evaluated ones.
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "paper_examples/cerone/table_case.hpp"

namespace hw::cerone {

struct Violation {
  std::string property;   // "truth", "order", "horizon" or "witness"
  std::string parameter;
  std::string text;       // what is outside what, with the values
  double excess = 0.0;    // by how much (absolute), beyond the tolerance
  nlohmann::json to_json() const;
};

// Every violation among `cases` (cases of different SNR, seed or N are never compared with each other).
std::vector<Violation> CheckTableProperties(const std::vector<TableCase>& cases, double tolerance = 1e-6);

// The property descriptions as printed with the tables.
std::string PropertiesText(double tolerance);

}  // namespace hw::cerone
