#pragma once
// Esmaeilani, Ghaisari & Bagherzadeh, "Hammerstein–Wiener identification of industrial plants:
// a pressure control valve case study", IET Control Theory Appl. 2020 (paper 002).
//
// Reading of the paper used here (SISO):
//   x_{t+1} = A x_t + b (f(u_t) + v_t) + mu_t,      g^{-1}(y_t) = C x_t + d (f(u_t) + v_t) + e_t,
// with the observable canonical form of eq. 4: A = [0 .. 0 -a_n; 1 0 .. -a_{n-1}; ..; 0 .. 1 -a_1],
// C = [0 .. 0 1], and the paper's vector a = [a_n, ..., a_1] (last column of A is -a), b = vec(B).
// v = eta + eps_f is the input-side noise. f and g^{-1} are ordered pairs (u'_k, f'_k), (y'_k, g'_k)
// on evenly spaced grids; f = Omega_f f', g^{-1}(y) = Omega_g g' with linear (hat-function)
// interpolation, linear extrapolation outside the grid (eq. 7; the paper's "value at the centre of a
// sub-region" is replaced by nodes at the grid points so that the map is continuous).
// Unknowns: every state x_t of every segment (so each segment has its own initial condition), f', g',
// v, a, b, d (Theorems 1-2). Residual theta = [mu; e; v] (eq. 8b) with optional weights; the paper
// minimises theta^T theta subject to linear constraints on f', g' (eqs. 19-20) by the SQP of
// Theorem 3: Gauss-Newton Hessian J^T J, one convex QP per iteration. We add a backtracking step
// length (the constraints are linear, so every step on the segment stays feasible) and stop on the
// relative decrease of theta^T theta (the paper's "decrease rate").
//
// Mapping to the project's transfer-function convention z_t = -sum a_i z_{t-i} + sum b_j x_{t-delay-j}:
//   G(q) = d + (B_n q^{n-1} + ... + B_1) / (q^n + a_1 q^{n-1} + ... + a_n), so
//   project a = [a_1, ..., a_n] = reverse(paper a);
//   project b = [d, c_1, ..., c_n] with delay 0, c_k = B_{n-k+1} + d a_k   (B_i = paper b[i-1]);
//   if d is fixed to 0: project b = [c_1, ..., c_n] with delay 1.
// Paper's valve result a = [-0.0009 0.7650 -1.7484], b = [0.7959 -1.7600 0.9884], d = 0 becomes
// project a = [-1.7484, 0.7650, -0.0009], b = [0.9884, -1.7600, 0.7959], delay 1.
// The output map stored in the model is g itself: the identified g^{-1} pairs are made monotone
// (running max/min) and swapped into pairs (z = g'_k - m_e, w = y'_k); with clamp_output the map is held
// constant outside the identified z range (hard saturation: y was never observed beyond the grid).
#include <string>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include "core/hw_model.hpp"
#include "estimators/esmaeilani/sparse_qp.hpp"

namespace hw::esmaeilani {

// One recorded operation (own initial condition).
struct Segment {
  std::vector<double> u, y;
  std::string name;
};

// Known information about one static function (eqs. 19-22), in the function's own argument.
struct FunctionConstraints {
  bool has_range = false;
  double range_lower = 0.0, range_upper = 0.0;  // value range at every grid node
  struct Slope {
    double from, to, lower, upper;  // slope limits on the part of the argument range [from, to]
  };
  std::vector<Slope> slopes;
  struct Point {
    double at, lower, upper;  // f(at) in [lower, upper]; a known point has lower == upper
  };
  std::vector<Point> points;
};

struct Constraints {
  FunctionConstraints f, g_inverse;
  bool fix_d_zero = false;  // no direct feedthrough (the paper's valve result has d = 0)
  // Known physical range of the measured output y (e.g. valve travel 0..100 %). The output map then
  // extrapolates g linearly beyond the identified pairs and saturates only at these limits; without it,
  // g is held constant outside the range of y seen in the estimation data.
  bool has_output_range = false;
  double output_lower = 0.0, output_upper = 0.0;
  // >= 0: samples with y within this distance of an output limit are saturated (censored): their output
  // equation is replaced by "the state is beyond g^{-1}(limit -+ 2 tol)". Use a bound on the output
  // measurement noise. Needs output_range, d = 0 and a monotone g^{-1} (slope limit over the output range).
  double saturation_tolerance = -1.0;
  // JSON: {"f": {"range": [lo, hi], "slopes": [{"from":..,"to":..,"min":..,"max":..}],
  //              "points": [[at, value]] or [[at, lo, hi]]}, "g_inverse": {...}, "d": 0,
  //        "output_range": [lo, hi]}
  static Constraints FromJson(const nlohmann::json& j, const std::string& source);  // throws InputError
  static Constraints Load(const std::string& path);
  nlohmann::json ToJson() const;
};

struct Options {
  int order = 3;
  int grid_f = 12, grid_g = 12;
  double weight_state = 1.0, weight_output = 1.0, weight_noise = 1.0;  // residual weights (paper: 1)
  int max_iterations = 100;
  double relative_decrease = 1e-7;  // stop when (cost_k - cost_{k+1}) / cost_k falls below
  // Levenberg-Marquardt term lambda * diag(J^T J) (an addition to Theorem 3: the pure Gauss-Newton step
  // of this bilinear problem overshoots). lambda starts at `damping`, grows when the step had to be
  // shortened, shrinks (not below `damping`) when the full step was taken.
  double damping = 1e-6;
  bool clamp_output = true;
  // After each joint Gauss-Newton step, re-solve the unknowns that enter linearly for the new (a, b, d)
  // exactly (one more QP, undamped). The residual is separable (linear in x, f', g', v, m_e for a fixed
  // linear block, Lemma 1 of the paper); the joint step alone crawled on the valve case (cost still
  // falling 1 %/iteration after 100 iterations; with it the cost after 100 iterations is 30 % lower, but
  // validation fits did not improve, see docs/esmaeilani.md). false = the paper's iteration of Theorem 3.
  bool reproject = false;
  // Estimate m_e, the mean of the output-equation disturbance (the paper's beta^[1] term). It absorbs
  // the offset of g^{-1}, so that two known points of g^{-1} only fix its (arbitrary) affine normalisation.
  bool estimate_output_offset = true;
  // Starting point: nullptr -> the paper's (identity maps, ARX linear block); otherwise this model's
  // a, b, d and its f, g^{-1} evaluated on the new grids (warm start, e.g. from a previous estimate).
  const struct EsmaeilaniModel* initial = nullptr;
  // Output-error refinement (not in the paper; see RefineOutputError): after the SQP, minimise the
  // simulation error sum_s ||y_s - yhat_s(theta)||^2 of the estimation operations. false = the paper.
  bool refine_output_error = false;
  int oe_max_iterations = 100;
  // false (default): each operation starts at the model's steady state at its first input, the assumption
  // the validation makes too (operations recorded from rest). true: each operation's initial state is an
  // unknown of the refinement (started at the SQP's x_1). On the valve case the free initial states
  // absorbed the input dead band (an operation starting in output saturation leaves x_1 unobservable):
  // validation fits 97.2 / 94.5 / 93.2 % instead of 98.7 / 98.6 / 98.7 % (docs/esmaeilani.md).
  bool oe_estimate_initial_states = false;
  QpOptions qp;
  bool IsValid(std::string* error) const;
};

// The identified model in the paper's parametrisation.
struct EsmaeilaniModel {
  std::vector<double> a, b;  // paper order: a = [a_n..a_1], b = vec(B)
  double d = 0.0;
  double output_offset = 0.0;  // m_e: g^{-1}(y_t) = C x_t + d f_t + m_e; folded into the output map
  bool has_output_range = false;  // from Constraints: where g saturates when clamping (see OutputMap)
  double output_lower = 0.0, output_upper = 0.0;
  std::vector<double> u_grid, f_values;      // ordered pairs of f
  std::vector<double> y_grid, ginv_values;   // ordered pairs of g^{-1}
  std::vector<std::vector<double>> initial_states;  // identified x_1 of each segment

  double F(double u) const;     // f by interpolation
  double Ginv(double y) const;  // g^{-1} by interpolation
  // g as ordered pairs (see header comment). clamp: hold g constant beyond the known output range if
  // there is one (linear extrapolation up to it), else beyond the identified pairs; !clamp: extrapolate.
  StaticMap OutputMap(bool clamp) const;
  HwModel ToHwModel(bool clamp_output = true) const;
  // State-space simulation; x0 empty -> steady state at the first input (zero if A has a unit pole).
  std::vector<double> Simulate(const std::vector<double>& u, std::vector<double> x0 = {},
                               bool clamp_output = true) const;
  std::vector<double> SteadyState(double u) const;
  nlohmann::json ToJson() const;  // the paper's parametrisation, written next to the project model
};

// Output-error (simulation-error) refinement, see RefineOutputError.
struct OutputErrorSummary {
  bool ran = false, improved = false;
  std::string message;
  int iterations = 0, parameters = 0, residuals = 0, qp_solves = 0, simulations = 0;
  double initial_cost = 0.0, final_cost = 0.0;  // sum over operations of ||y - yhat||^2
  std::vector<double> cost_history;
  double seconds = 0.0, qp_seconds = 0.0;
  double max_constraint_violation = 0.0;  // of the refined pairs against the known-information rows
};

struct Summary {
  enum class Status { kConverged, kMaxIterations, kFailed };
  Status status = Status::kFailed;
  std::string message;
  int iterations = 0;
  int unknowns = 0, equations = 0, constraints = 0;
  double initial_cost = 0.0, final_cost = 0.0;
  std::vector<double> cost_history;
  std::vector<double> step_lengths;  // accepted fraction of each Gauss-Newton step
  double seconds = 0.0, qp_seconds = 0.0;
  double setup_seconds = 0.0;  // residual, Jacobian, J^T J and QP data per iteration
  int qp_iterations = 0;
  int qp_solves = 0;
  int censored_samples = 0;  // samples at a known output saturation (output equation -> inequality)
  // seconds above is the SQP alone; the optional refinement reports its own time here.
  OutputErrorSummary output_error;
  bool ok() const { return status != Status::kFailed; }
};

// The model file `hwbounds esmaeilani` writes: the project model (docs/input_output.md: Model JSON) of the estimate, with
// the paper's parametrisation, the known information and the final costs under "esmaeilani".
nlohmann::json ModelFileJson(const EsmaeilaniModel& m, const Options& options, const Constraints& constraints,
                             const Summary& summary);

// Throws InputError for unusable input: bad options, too few data for the unknowns, contradictory
// constraints (reported by the first QP as infeasible).
EsmaeilaniModel Estimate(const Options& options, const std::vector<Segment>& segments,
                         const Constraints& constraints, Summary* summary);

// Output-error refinement of an estimate (an addition to the paper). The paper's equation-error
// criterion (eq. 8b) cannot represent samples in output saturation (g^{-1} is one value there), so its
// minimiser is biased away from the true system (docs/esmaeilani.md). This stage minimises
//   sum over segments of ||y_s - yhat_s(theta)||^2,
// yhat simulated exactly as EsmaeilaniModel::Simulate does (f pairs interpolated, observable-canonical
// (a, b, d), g = inverse of the g^{-1} pairs, saturating at the known output range), over
// theta = [f'; g'; a; b; d; m_e; initial state of each segment (optional, else the steady state at the
// segment's first input)], by Levenberg-Marquardt:
// forward-difference Jacobian, and each step one convex QP (Ipopt) with the same known-information rows
// on f', g' as the SQP (ranges, slopes, known points) and d = 0 if known, so every iterate satisfies
// them. Only steps that lower the simulation error are accepted: the result is never worse than `start`
// on the estimation data. The grids are those of `start` (from Estimate on the same segments).
EsmaeilaniModel RefineOutputError(const Options& options, const std::vector<Segment>& segments,
                                  const Constraints& constraints, const EsmaeilaniModel& start,
                                  OutputErrorSummary* summary);

}  // namespace hw::esmaeilani
