#pragma once
// The text a person reads after an exact-set run: one row per parameter with the exact set's guaranteed
// interval, the inner hull and their ratio, the outer set D^ss(n)'s interval beside it, and the truth when
// given; then the assumptions and the stage-2 counts.
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "exact/exact_bounds.hpp"

namespace hw::exact {

struct ExactReportOptions {
  std::vector<double> truth;                       // empty: no coverage column
  std::vector<std::pair<double, double>> outer;    // D^ss(n) intervals per parameter (empty: none)
  std::string outer_label = "D^ss(n)";
  double stage1_seconds = 0.0;
  std::string model_class;
};

std::string ExactReport(const ExactBoundsSummary& summary, const ExactReportOptions& options);
// Whether every true value lies in its exact interval (true without a truth).
bool TruthInside(const ExactBoundsSummary& summary, const std::vector<double>& truth);

}  // namespace hw::exact
