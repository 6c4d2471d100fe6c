#pragma once
// The equivalent noise level: the SNR at which our inner hulls are as wide as the paper's intervals.
//
// Criterion: c(SNR) = median over the (horizon, parameter) pairs the paper prints of log(inner half-width /
// paper half-width). Less noise shrinks D^ss(n), so c falls with the SNR; the equivalent SNR is where c crosses 0,
// found by bisection on the SNR in dB (the noise bound is 10^(-SNR/20) times a constant of the realisation, so
// this is a bisection on log(noise bound)). The median ignores the few parameters whose hull reaches the prior
// box or stays far from the paper's. Inner hulls are lower bounds of the exact intervals, so the exact
// equivalent SNR is at least the one found.
#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace hw::cerone {

struct WidthRatio {
  int horizon = 2;
  std::string parameter;
  double inner_half = 0.0, paper_half = 0.0;
  double ratio() const { return inner_half / paper_half; }
};

struct SnrEvaluation {
  double snr_db = 0.0;
  double criterion = 0.0;  // median log ratio
  std::vector<WidthRatio> ratios;
  // The horizons present in `ratios`, ascending, and the criterion over each one's ratios alone: where a table's
  // own crossing lies when the bisection runs on several tables at once.
  std::vector<int> horizons() const;
  double criterion_of(int horizon) const;
};

struct EquivalentSnrOptions {
  double low_db = 31.0, high_db = 60.0;
  int iterations = 6;  // bisection steps after the two ends
  bool IsValid(std::string* error) const;
};

struct EquivalentSnrResult {
  bool bracketed = false;  // c(low) >= 0 >= c(high); otherwise `best` is the end closest to 0
  SnrEvaluation best;      // the evaluation with the smallest |criterion|
  std::vector<SnrEvaluation> evaluations;  // in the order they ran
  nlohmann::json to_json() const;
};

// The criterion of a set of ratios (NaN when none is usable: a zero or non-finite width).
double MedianLogRatio(const std::vector<WidthRatio>& ratios);

// What the criterion means, as printed.
std::string EquivalentSnrCriterionText();

// Bisection on the SNR; `ratios_at(snr_db)` computes the inner hulls at that SNR and their ratios.
EquivalentSnrResult FindEquivalentSnr(const EquivalentSnrOptions& options,
                                      const std::function<std::vector<WidthRatio>(double)>& ratios_at);

}  // namespace hw::cerone
