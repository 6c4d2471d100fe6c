#include "paper_examples/cerone/table_properties.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

namespace hw::cerone {

nlohmann::json Violation::to_json() const {
  return {{"property", property}, {"parameter", parameter}, {"text", text}, {"excess", excess}};
}

std::string PropertiesText(double tolerance) {
  return fmt::format(
      "Checked on every table: the truth inside every outer interval (Property 2); order delta+1 inside order "
      "delta (Property 3); n = 3 inside n = 2 (Property 4); every inner witness of D^ss(n') inside every outer "
      "interval of D^ss(n), n <= n'. Containment allows {:g} * max(1, |value|) for the outward rounding of "
      "verified endpoints.",
      tolerance);
}

namespace {

bool SameData(const TableCase& a, const TableCase& b) {
  return a.snr_db == b.snr_db && a.seed == b.seed && a.samples == b.samples;
}

// Checks [lo, hi] ⊆ outer up to the tolerance; a non-finite value counts as outside.
void CheckInside(double lo, double hi, const dss::ParameterInterval& outer, double tolerance,
                 const std::string& property, const std::string& inner_text, const std::string& outer_text,
                 std::vector<Violation>* out) {
  const double below = outer.lower.value - lo - tolerance * std::max(1.0, std::abs(lo));
  const double above = hi - outer.upper.value - tolerance * std::max(1.0, std::abs(hi));
  if (below <= 0 && above <= 0) return;
  const double excess = std::isnan(below) || std::isnan(above) ? INFINITY : std::max(below, above);
  out->push_back({property, outer.name,
                  fmt::format("{} [{:.9g}, {:.9g}] is not inside {} [{:.9g}, {:.9g}]", inner_text, lo, hi, outer_text,
                              outer.lower.value, outer.upper.value),
                  excess});
}

std::string OuterText(const TableCase& c, int order) { return fmt::format("order {} ({})", order, c.label()); }

void CheckTruth(const TableCase& c, double tolerance, std::vector<Violation>* out) {
  for (const auto& [order, run] : c.outer)
    for (const auto& iv : run.intervals) {
      const auto k = std::find(c.names.begin(), c.names.end(), iv.name) - c.names.begin();
      if (k >= static_cast<long>(c.truth.size())) continue;
      CheckInside(c.truth[k], c.truth[k], iv, tolerance, "truth", "the truth", OuterText(c, order), out);
    }
}

// Every interval of run `inner_order` of case `a` inside the same parameter's interval of run `outer_order` of `b`.
void CheckRunInside(const TableCase& a, int inner_order, const TableCase& b, int outer_order, double tolerance,
                    const std::string& property, std::vector<Violation>* out) {
  for (const auto& iv : a.outer.at(inner_order).intervals)
    if (const auto* outer = FindInterval(b.outer.at(outer_order), iv.name))
      CheckInside(iv.lower.value, iv.upper.value, *outer, tolerance, property, OuterText(a, inner_order),
                  OuterText(b, outer_order), out);
}

void CheckOrders(const TableCase& c, double tolerance, std::vector<Violation>* out) {
  for (const auto& [low, run_low] : c.outer)
    for (const auto& [high, run_high] : c.outer)
      if (high > low) CheckRunInside(c, high, c, low, tolerance, "order", out);
}

void CheckHorizons(const TableCase& shorter, const TableCase& longer, double tolerance, std::vector<Violation>* out) {
  for (const auto& [order, run] : longer.outer)
    if (shorter.outer.count(order)) CheckRunInside(longer, order, shorter, order, tolerance, "horizon", out);
}

void CheckWitnesses(const TableCase& outer_case, const TableCase& inner_case, double tolerance,
                    std::vector<Violation>* out) {
  for (const auto& [order, run] : outer_case.outer)
    for (const auto& inner : inner_case.inner.intervals)
      if (const auto* outer = FindInterval(run, inner.name); outer && inner.found)
        CheckInside(inner.lower, inner.upper, *outer, tolerance, "witness",
                    fmt::format("the inner hull ({})", inner_case.label()), OuterText(outer_case, order), out);
}

}  // namespace

std::vector<Violation> CheckTableProperties(const std::vector<TableCase>& cases, double tolerance) {
  std::vector<Violation> violations;
  for (const auto& c : cases) {
    CheckTruth(c, tolerance, &violations);
    CheckOrders(c, tolerance, &violations);
  }
  for (const auto& a : cases)
    for (const auto& b : cases) {
      if (!SameData(a, b) || a.horizon > b.horizon) continue;
      if (a.horizon < b.horizon) CheckHorizons(a, b, tolerance, &violations);
      CheckWitnesses(a, b, tolerance, &violations);
    }
  return violations;
}

}  // namespace hw::cerone
