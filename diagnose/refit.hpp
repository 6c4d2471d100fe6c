#pragma once
// Estimation for the diagnosis: output-error fitting of the nominal model and joint refit of an
// effect block with the model's own parameters.
//
// Method (why): the effect parameters enter the simulation non-smoothly and the cost has local
// minima, so each candidate is first searched on a grid scaled to the recording (for input blocks the
// linear numerator is re-solved by least squares at every grid point, with the denominator held, which
// is exact output-error for fixed poles); the best grid points are then refined jointly with the
// linear block (and polynomial maps) by Levenberg–Marquardt on the simulation error, with
// forward-difference Jacobians. Search-only parameters (integer delay, quantisation step, relay
// threshold) are refined by a finer local grid instead.
#include <functional>
#include <string>
#include <vector>

#include "core/hw_model.hpp"
#include "diagnose/effects.hpp"

namespace hw::diagnose {

struct LmOptions {
  int max_iterations = 100;
  double relative_tolerance = 1e-9;
  bool IsValid(std::string* error) const;
};

struct LmSummary {
  bool converged = false;
  int iterations = 0;
  double initial_cost = 0.0, final_cost = 0.0;  // sum of squared residuals
};

// Minimises ||residual(p)||^2 by Levenberg–Marquardt with forward-difference Jacobians.
// `scale[i]` sets the finite-difference step of p[i] (relative to max(|p_i|, scale_i)).
std::vector<double> LevenbergMarquardt(const std::function<void(const std::vector<double>&, std::vector<double>*)>& residual,
                                       std::vector<double> p, const std::vector<double>& scale, const LmOptions& options,
                                       LmSummary* summary);

// A recording segment with the first `skip` samples excluded from every cost (transient from rest).
struct Segment {
  const std::vector<double>* u = nullptr;
  const std::vector<double>* y = nullptr;
  std::size_t skip = 0;
};

double SumSquaredError(const AugmentedModel& m, const Segment& s);

// Nominal structures users can ask for instead of a model file.
struct NominalSpec {
  int na = 2, nb = 2, delay = 0;      // linear: z_t = -sum_{1..na} a z + sum_{0..nb-1} b x_{t-delay-j}
  int input_degree = 1;               // hw: polynomial input map of this degree (1 = identity)
  int output_degree = 1;              // hw: polynomial output map of this degree (1 = identity)
  bool IsValid(std::string* error) const;
  // "linear:NA,NB[,DELAY]" or "hw:NA,NB,PIN,POUT[,DELAY]"; throws InputError.
  static NominalSpec Parse(const std::string& text);
};

// Output-error fit of the nominal structure: ARX, Steiglitz–McBride passes, then Levenberg–Marquardt.
HwModel FitNominal(const NominalSpec& spec, const Segment& data);

struct RefitOptions {
  bool refit_maps = true;   // also re-estimate polynomial map coefficients (first coefficient held at its value)
  bool fit_output_offset = true;  // estimate a constant output offset with every refit (baseline included)
  int keep_grid_points = 3; // grid points refined by LM
  LmOptions lm;
  bool IsValid(std::string* error) const;
};

struct RefitResult {
  AugmentedModel model;
  double sse = 0.0;      // on the fitting segment
  int extra_parameters = 0;  // effect parameters actually estimated (one-sided saturations count 1)
};

// Refit of the nominal model with no block (the fair baseline: same optimiser, same data).
RefitResult RefitNominal(const HwModel& nominal, const Segment& data, const RefitOptions& options);
// Joint refit of one effect block at one location with the model's parameters.
// `output_offset` is the starting output offset (e.g. the baseline refit's).
RefitResult RefitWithEffect(const HwModel& nominal, Effect effect, Location location, const Segment& data,
                            const RefitOptions& options, double output_offset = 0.0);

// Reflects roots of A(q) outside the unit circle inside it (keeps the model simulable).
std::vector<double> StabilisedDenominator(const std::vector<double>& a);

}  // namespace hw::diagnose
