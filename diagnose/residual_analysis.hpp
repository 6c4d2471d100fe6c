#pragma once
// Residual analysis of a simulation error e_t = y_t - yhat_t (Ljung, System Identification, ch. 16.6):
// noise level, windows where the error exceeds what the noise explains, the operating condition that
// characterises those windows, and the whiteness / input cross-correlation tests.
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

namespace hw::diagnose {

// Robust white-noise standard deviation from the residual's first differences
// (1.4826 MAD(diff e) / sqrt 2): a smooth model error barely moves it, isolated bursts do not move it.
double EstimateNoiseStd(const std::vector<double>& e, std::size_t skip);

struct WindowOptions {
  int length = 0;           // sliding-window length in samples; 0 = auto (N/200 clamped to [8, 40])
  // Family-wise false-alarm probability over the recording's N/L disjoint windows: a window is flagged
  // when its mean square exceeds sigma^2 chi^2_L(1 - alpha L / N) / L (Bonferroni), so that a recording
  // the model explains is flagged nowhere with probability about 1 - alpha.
  double alpha = 0.05;
  bool IsValid(std::string* error) const;
  int Resolve(std::size_t n) const;
  double Threshold(std::size_t n) const;  // in units of sigma^2
};

// Samples (mask) and merged [start, end] index windows where the local mean-square error exceeds the noise.
std::vector<bool> MismatchMask(const std::vector<double>& e, double noise_std, std::size_t skip,
                               const WindowOptions& options);
std::vector<std::pair<std::size_t, std::size_t>> MaskToWindows(const std::vector<bool>& mask);

// Operating conditions evaluated per sample, e.g. "u", "|du|", "time since reversal of u".
struct Condition {
  std::string name;        // machine name: u, y, abs_u, abs_y, du, abs_du, dy, abs_dy, since_rev_u, since_rev_y,
                           // dir_u, dir_y (sign of the last non-zero change)
  std::string words;       // how a person reads it
  std::vector<double> values;
};
std::vector<Condition> OperatingConditions(const std::vector<double>& u, const std::vector<double>& y_model);

struct Region {
  bool found = false;
  std::string condition;     // machine name of the condition
  std::string relation;      // "above" or "below"
  double threshold = 0.0;
  double precision = 0.0;    // fraction of samples meeting the rule that lie in the mismatch windows
  double recall = 0.0;       // fraction of mismatch samples meeting the rule
  double lift = 0.0;         // mean squared error where the rule holds / where it does not (at most 1e6)
  std::string description;   // e.g. "within 6 samples after a reversal of u"
  // Signed evidence: the split of one condition across which the mean error changes most (in units of
  // the error's standard deviation), e.g. a backlash offset that follows the direction of u.
  struct Bias {
    bool found = false;
    std::string condition, description;
    double threshold = 0.0, mean_above = 0.0, mean_below = 0.0, effect_size = 0.0;
  } bias;
  nlohmann::json to_json() const;
};
// The single threshold rule on one condition that best matches the mismatch mask (F1), weighted by
// the squared signal e so that a rule must also concentrate it. `subject` names e in the text
// ("error" for a residual, "change" for what an effect block changes in the prediction).
Region CharacteriseRegion(const std::vector<Condition>& conditions, const std::vector<bool>& mask,
                          const std::vector<double>& e, std::size_t skip, const std::string& subject = "error");

struct CorrelationTest {
  double statistic = 0.0;  // N sum rho^2
  int dof = 0;
  double threshold = 0.0;  // chi^2 99 % quantile
  bool passed = true;
  std::vector<double> rho;  // normalised correlations per lag
  nlohmann::json to_json() const;
};
CorrelationTest WhitenessTest(const std::vector<double>& e, std::size_t skip, int max_lag);
// Cross-correlation of e with u at lags 0..max_lag (u leading e).
CorrelationTest InputCorrelationTest(const std::vector<double>& e, const std::vector<double>& u, std::size_t skip,
                                     int max_lag);

double ChiSquareQuantile(double p, int dof);  // Wilson–Hilferty approximation

}  // namespace hw::diagnose
