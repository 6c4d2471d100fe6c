#pragma once
// Continuous-time simulation of the HW system of Brouri's paper (paper 000):
//   u -> F (backlash, eq. 1, or backlash-inverse, eq. 2) -> v -> G(s) -> w -> h(w) = x -> y = x + xi.
// Sampling convention: the input is held constant between samples (zero-order hold, as a DAC does)
// and y_k = h(w(k Ts)) + xi_k. G(s) is discretised exactly for this hold (augmented-matrix expm),
// so the simulator adds no integration error: the only approximation is the hold itself, which the
// frequency stage accounts for (see frequency_stage.hpp).
#include <complex>
#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Dense>
#include <nlohmann/json.hpp>

#include "core/input_error.hpp"

namespace hw::brouri {

// Runs parse() (JSON access that may throw), turns JSON errors into InputError naming `what`, and
// checks the result's IsValid.
template <class T, class Parse>
T ParseValidated(const std::string& what, Parse&& parse) {
  T value;
  try {
    value = parse();
  } catch (const nlohmann::json::exception& e) {
    throw InputError(what + " JSON: " + e.what());
  }
  std::string err;
  if (!value.IsValid(&err)) throw InputError(what + ": " + err);
  return value;
}

// Polynomials are ascending coefficient vectors: p(x) = sum_i c[i] x^i.
double PolyEval(const std::vector<double>& c, double x);
// q(x) = p(x + shift) (Taylor shift; eq. 12 uses it to move the root d+ to the origin).
std::vector<double> PolyShift(const std::vector<double>& c, double shift);
// Real roots (|imaginary part| <= tol * (1 + |root|)) of a polynomial of degree >= 1.
std::vector<double> PolyRealRoots(const std::vector<double>& c, double tol = 1e-7);
// Least-squares polynomial fit of the given degree (exact interpolation when points == degree + 1).
std::vector<double> PolyFit(const std::vector<double>& x, const std::vector<double>& y, int degree);

// Border parameters of eq. 1 (backlash) or eq. 2 (backlash-inverse): slopes S^a, S^d and offsets d+, d-.
struct BacklashParams {
  double slope_up = 1.0;     // S^a
  double offset_up = 0.5;    // d+
  double slope_down = 1.0;   // S^d
  double offset_down = -0.5; // d-
  bool IsValid(std::string* error) const;
};

enum class OperatorKind { kBacklash, kBacklashInverse };
const char* ToString(OperatorKind kind);

// Discrete-time memory operator, one input sample at a time. Starts at rest (input 0, output 0).
//  kBacklash (eq. 1): v moves along S^a(u - d+) when u pushes it up, along S^d(u - d-) when u
//    pushes it down, and stays put (horizontal path) in between.
//  kBacklashInverse (eq. 2): v = u/S^a + d+ while u increases, u/S^d + d- while it decreases,
//    unchanged while u is constant.
class MemoryOperator {
 public:
  MemoryOperator(OperatorKind kind, const BacklashParams& params) : kind_(kind), p_(params) {}
  double Step(double u);
  OperatorKind kind() const { return kind_; }
  const BacklashParams& params() const { return p_; }

 private:
  OperatorKind kind_;
  BacklashParams p_;
  double last_u_ = 0.0, v_ = 0.0;
};

// The same operator written as two lines in the (u, v) plane: v = slope (u - root) on the path taken
// while u increases ("up") and while it decreases ("down"). Stage 1 estimates exactly these lines.
struct OperatorLines {
  double slope_up = 1.0, root_up = 0.0, slope_down = 1.0, root_down = 0.0;
};
OperatorLines LinesOf(OperatorKind kind, const BacklashParams& p);
// Inverse map: the operator of kind `kind` whose lines are `lines`.
BacklashParams ParamsFromLines(OperatorKind kind, const OperatorLines& lines);

// Rational G(s) = num(s)/den(s), coefficients in DESCENDING powers of s (num degree <= den degree).
struct TransferFunction {
  std::vector<double> num, den;
  bool IsValid(std::string* error) const;  // proper, den leading coefficient nonzero, stable
  std::complex<double> Response(double omega) const;  // G(j omega)
  double StaticGain() const;                          // G(0)
};

// Exact zero-order-hold discretisation: x_{k+1} = Phi x_k + Gamma v_k, w_k = C x_k + D v_k.
class ZohSystem {
 public:
  ZohSystem(const TransferFunction& g, double sample_time);
  double Step(double v);  // returns w at the current sample, then advances the state one sample
  void Reset() { x_.setZero(); }

 private:
  Eigen::MatrixXd phi_;
  Eigen::VectorXd gamma_, c_, x_;
  double d_ = 0.0;
};

struct BacklashHwSystem {
  OperatorKind kind = OperatorKind::kBacklash;
  BacklashParams backlash;
  TransferFunction g;
  std::vector<double> h;  // ascending coefficients, h[0] = h(0) = 0
  double noise_std = 0.0;

  bool IsValid(std::string* error) const;
  // The paper's Section 6 system (eq. 29): G = 0.2/((s+0.5)(s+0.2)), h = 0.2x^5 - 0.42x^3 + 0.25x,
  // S^a = S^d = 1, d+ = 0.5, d- = -0.5, sigma = 0.01.
  static BacklashHwSystem PaperExample();
  // The normalised model of eq. 4: operator divided by its "up" slope, G(0) = 1, h absorbing both.
  // Its input-output behaviour is identical to the original's.
  BacklashHwSystem Normalised() const;
  // {"operator": "backlash"|"backlash-inverse", "S_a", "d_plus", "S_d", "d_minus",
  //  "num": [...], "den": [...] (descending powers of s), "h": [h0, h1, ...], "noise_std"}
  nlohmann::json to_json() const;
  static BacklashHwSystem from_json(const nlohmann::json& j);  // throws InputError
};

// Simulates the sampled system on input u (one value per sample, held between samples).
// `precompensator`, when given, is applied to u first (stage 2's backlash-inverse, Fig. 8).
struct SimulationResult {
  std::vector<double> v, w, x, y;
};
SimulationResult Simulate(const BacklashHwSystem& system, const std::vector<double>& u, double sample_time,
                          std::uint64_t seed, const MemoryOperator* precompensator = nullptr);

}  // namespace hw::brouri
