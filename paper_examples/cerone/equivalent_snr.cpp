#include "paper_examples/cerone/equivalent_snr.hpp"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <set>
#include <stdexcept>

namespace hw::cerone {

bool EquivalentSnrOptions::IsValid(std::string* error) const {
  if (!(std::isfinite(low_db) && std::isfinite(high_db) && low_db < high_db))
    return *error = "equivalent SNR: the range must be two finite values LOW < HIGH (dB)", false;
  if (iterations < 0 || iterations > 30) return *error = "equivalent SNR: iterations must be in 0..30", false;
  return true;
}

double MedianLogRatio(const std::vector<WidthRatio>& ratios) {
  std::vector<double> logs;
  for (const auto& r : ratios) {
    const double v = std::log(r.ratio());
    if (std::isfinite(v)) logs.push_back(v);
  }
  if (logs.empty()) return NAN;
  std::sort(logs.begin(), logs.end());
  const std::size_t m = logs.size() / 2;
  return logs.size() % 2 ? logs[m] : 0.5 * (logs[m - 1] + logs[m]);
}

std::vector<int> SnrEvaluation::horizons() const {
  std::set<int> seen;
  for (const auto& r : ratios) seen.insert(r.horizon);
  return {seen.begin(), seen.end()};
}

double SnrEvaluation::criterion_of(int horizon) const {
  std::vector<WidthRatio> of_horizon;
  std::copy_if(ratios.begin(), ratios.end(), std::back_inserter(of_horizon),
               [&](const WidthRatio& r) { return r.horizon == horizon; });
  return MedianLogRatio(of_horizon);
}

std::string EquivalentSnrCriterionText() {
  return "criterion: median over the (n, parameter) pairs of the paper's tables of log(inner half-width / paper "
         "half-width); the equivalent SNR is where it crosses 0 (bisection on the SNR in dB, one seed)";
}

nlohmann::json EquivalentSnrResult::to_json() const {
  auto evaluation_json = [](const SnrEvaluation& e) {
    nlohmann::json ratios = nlohmann::json::array();
    for (const auto& r : e.ratios)
      ratios.push_back({{"n", r.horizon}, {"parameter", r.parameter}, {"inner_half_width", r.inner_half},
                        {"paper_half_width", r.paper_half}, {"ratio", r.ratio()}});
    nlohmann::json by_horizon = nlohmann::json::object();
    for (int n : e.horizons()) by_horizon[std::to_string(n)] = e.criterion_of(n);
    return nlohmann::json{
        {"snr_db", e.snr_db}, {"criterion", e.criterion}, {"criterion_by_horizon", by_horizon}, {"ratios", ratios}};
  };
  nlohmann::json all = nlohmann::json::array();
  for (const auto& e : evaluations) all.push_back(evaluation_json(e));
  return {{"criterion", EquivalentSnrCriterionText()}, {"bracketed", bracketed}, {"best", evaluation_json(best)},
          {"evaluations", all}};
}

EquivalentSnrResult FindEquivalentSnr(const EquivalentSnrOptions& options,
                                      const std::function<std::vector<WidthRatio>(double)>& ratios_at) {
  std::string error;
  if (!options.IsValid(&error)) throw std::invalid_argument(error);
  EquivalentSnrResult result;
  auto evaluate = [&](double snr) {
    SnrEvaluation e{snr, 0.0, ratios_at(snr)};
    e.criterion = MedianLogRatio(e.ratios);
    result.evaluations.push_back(e);
    const bool closer = std::abs(e.criterion) < std::abs(result.best.criterion);
    if (result.evaluations.size() == 1 || closer || std::isnan(result.best.criterion)) result.best = e;
    return e.criterion;
  };
  double low = options.low_db, high = options.high_db;
  const double c_low = evaluate(low), c_high = evaluate(high);
  result.bracketed = c_low >= 0 && c_high <= 0;
  if (!result.bracketed) return result;
  for (int i = 0; i < options.iterations; ++i) {
    const double mid = 0.5 * (low + high);
    (evaluate(mid) >= 0 ? low : high) = mid;
  }
  return result;
}

}  // namespace hw::cerone
