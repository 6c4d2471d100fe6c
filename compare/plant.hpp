#pragma once
// Adapter: a discrete Hammerstein–Wiener plant or estimate in one comparable form, and the
// normalisation-free quantities every method is compared on.
//
// core's HwModel stores the output map w = g(z) directly; paper 001's class stores its inverse
// z = sum_k alpha_k w^k. `inverse_output`, when set, defines g as the inverse of that polynomial
// (unique only if it is monotone on the range used; otherwise the model cannot be simulated and
// every quantity that needs g is reported as not available).
//
// Quantities (invariant under the rescalings that relate the methods' parametrisations):
//   static curve     y_ss(u) = g(G(1) f(u))                       (steady-state input-output map)
//   frequency resp.  |G(e^{jw})| / |G(1)|                          (shape of the linear block)
//   validation fit   fit_percent of the simulated output against the noise-free true output,
//                    every model started in the steady state of the first input.
#include <complex>
#include <optional>
#include <string>
#include <vector>

#include "core/hw_model.hpp"

namespace hw::compare {

struct Plant {
  HwModel model;
  std::vector<double> inverse_output;  // z = sum_k c[k] w^(k+1); empty = use model.output

  // g(z); std::nullopt when inverse_output is not monotone near the solution.
  std::optional<double> output(double z) const;
  double static_gain() const;  // G(1)
  std::optional<double> steady_state(double u) const;
  double normalised_gain(double omega) const;  // |G(e^{j omega})| / |G(1)|
  // Simulation from the steady state of u[0] (warm-up of `warmup` samples of u[0], discarded).
  // Empty when g is not available somewhere on the trajectory.
  std::vector<double> simulate(const std::vector<double>& u, int warmup = 1000) const;
  // Checks the inverse polynomial is strictly monotone on [w_lo, w_hi] (derivative sign on a grid).
  bool inverse_monotone(double w_lo, double w_hi, int grid = 2001) const;
};

std::complex<double> FrequencyResponse(const LinearBlock& lin, double omega);

// Evaluates a polynomial without constant term: sum_k c[k] v^(k+1).
double PolyNoConstant(const std::vector<double>& c, double v);

}  // namespace hw::compare
