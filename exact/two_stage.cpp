#include "exact/two_stage.hpp"

#include <algorithm>

#include "exact/exact_report.hpp"

namespace hw::exact {

ParamBox StartBoxFromOuter(const dss::BoundsSummary& outer, const dss::HwOuterSet& set) {
  const auto& names = set.layout().names;
  ParamBox box;
  for (std::size_t k = 0; k < names.size(); ++k) box.emplace_back(set.box()[k].first, set.box()[k].second);
  for (const auto& iv : outer.intervals) {
    const std::size_t k = std::find(names.begin(), names.end(), iv.name) - names.begin();
    if (k < names.size())
      box[k] = Interval(std::max(box[k].lo, iv.lower.value), std::min(box[k].hi, iv.upper.value));
  }
  return box;
}

nlohmann::json ExactResultJson(const ExactBoundsSummary& exact, const nlohmann::json& outer_json,
                               const dss::BoundsSummary& outer, const std::vector<double>& truth) {
  nlohmann::json j = exact.to_json();
  j["set"] = "exact";
  j["outer_set_intervals"] = outer_json.at("intervals");
  j["outer_set"] = {{"horizon", outer.horizon}, {"order", outer.order}, {"wall_seconds", outer.wall_seconds}};
  for (const char* key : {"data", "data_warnings", "structure"})
    if (outer_json.contains(key)) j[key] = outer_json.at(key);
  if (!truth.empty()) {
    j["truth"] = truth;
    j["truth_covered"] = TruthInside(exact, truth);
  }
  return j;
}

}  // namespace hw::exact
