#pragma once
// The project's Hammerstein–Wiener model: input static map -> discrete LTI block -> output static map.
// One JSON format (documented in docs/input_output.md, "Model JSON") is written by the estimators and read by
// `simulate`, `diagnose` and `compare`.
//
// Linear block convention (paper 001 eq. 3, used everywhere in hwbounds):
//   z_t = -sum_{i=1..na} a_i z_{t-i} + sum_{j=0..nb} b_j x_{t-delay-j}
#include <functional>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

namespace hw {

struct StaticMap {
  enum class Kind { kIdentity, kPolynomial, kPiecewiseLinear };
  Kind kind = Kind::kIdentity;
  // kPolynomial: value = sum_k coefficients[k] * v^(k+1) (no constant term, as in paper 001's bases).
  std::vector<double> coefficients;
  // kPiecewiseLinear: ordered pairs (breakpoints ascending); linear extrapolation outside.
  std::vector<double> x, y;

  double operator()(double v) const;
  bool IsValid(std::string* error) const;
  nlohmann::json to_json() const;
  static StaticMap from_json(const nlohmann::json& j);  // throws InputError
  static StaticMap Polynomial(std::vector<double> c);
  static StaticMap PiecewiseLinear(std::vector<double> x, std::vector<double> y);
};

struct LinearBlock {
  std::vector<double> a;  // a_1..a_na
  std::vector<double> b;  // b_0..b_nb
  int delay = 0;          // extra input delay in samples

  bool IsValid(std::string* error) const;
  // True when every pole of 1 / (1 + a_1 q^-1 + ... + a_na q^-na) lies strictly inside the unit circle
  // (Schur-Cohn test); an unstable block's simulation grows without bound.
  bool is_stable() const;
  // Simulates from rest (zero initial state).
  std::vector<double> simulate(const std::vector<double>& x) const;
};

struct HwModel {
  StaticMap input;   // x = input(u)
  LinearBlock linear;
  StaticMap output;  // w = output(z)
  std::string name;

  bool IsValid(std::string* error) const;
  std::vector<double> simulate(const std::vector<double>& u) const;  // noise-free w
  nlohmann::json to_json() const;
  // Throws InputError, also for a key outside the format ("esmaeilani", the estimator's record, is part of
  // it); `extension_keys` are further keys a caller reads itself (e.g. an augmented model's effect block).
  static HwModel from_json(const nlohmann::json& j, const std::vector<std::string_view>& extension_keys = {});
  static HwModel load(const std::string& path);
  void save(const std::string& path) const;
};

// The checks of `simulate` (the CLI command and the Python function, one message each). `source` names the model
// in messages: its file, or "model".
// A model whose linear block is unstable (its output grows without bound) is refused unless `allow_unstable`.
void CheckStableOrAllowed(const HwModel& model, const std::string& source, bool allow_unstable);
// Every output sample finite; otherwise InputError naming the model, the first overflowing sample (1-based) and
// `where(t)`, that sample's origin (e.g. "rec.csv:12").
void CheckFiniteOutput(const std::vector<double>& w, const std::string& source,
                       const std::function<std::string(std::size_t)>& where);

// Fit percentage 100 (1 - ||y - yhat|| / ||y - mean(y)||) and RMSE: the project's figures of merit.
double fit_percent(const std::vector<double>& y, const std::vector<double>& yhat);
double rmse(const std::vector<double>& y, const std::vector<double>& yhat);

}  // namespace hw
