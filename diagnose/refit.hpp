#pragma once
// Estimation for the diagnosis: joint refit of effect blocks with the model's own parameters.
//
// Method (why): the effect parameters enter the simulation non-smoothly and the cost has local
// minima, so each candidate block is first searched on a grid scaled to the recording (for input
// blocks the linear numerator, the output offset and the initial state are re-solved by least squares
// at every grid point with the poles held, which is exact output error for fixed poles); the best grid
// points are then refined jointly with the linear block (and polynomial maps, offset, initial state) by
// Levenberg–Marquardt on the simulation error, with forward-difference Jacobians. Search-only
// parameters (integer delay, quantisation step, relay threshold) are refined by a finer local grid.
// Every step keeps the block parameters in their physical range (ClampToPhysicalRange).
#include <complex>
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

// A recording segment: costs over samples [skip, end) (end = 0: to the end of y); the simulation always
// starts at sample 0, so the first `skip` samples only warm it up.
struct Segment {
  const std::vector<double>* u = nullptr;
  const std::vector<double>* y = nullptr;
  std::size_t skip = 0;
  std::size_t end = 0;
  std::size_t End() const { return end == 0 || end > y->size() ? y->size() : end; }
  std::size_t Count() const { return End() > skip ? End() - skip : 0; }
};

double SumSquaredError(const AugmentedModel& m, const Segment& s);

struct RefitOptions {
  bool refit_maps = true;              // also re-estimate polynomial map coefficients (first one held)
  bool fit_output_offset = true;       // estimate a constant output offset with every refit
  bool estimate_initial_state = true;  // estimate z_{-1..-na} (recordings that do not start from rest)
  int keep_grid_points = 3;            // grid points refined by LM
  LmOptions lm;
  bool IsValid(std::string* error) const;
};

struct RefitResult {
  AugmentedModel model;
  double sse = 0.0;          // on the fitting segment
  int extra_parameters = 0;  // effect parameters actually estimated (one-sided saturations count 1)
};

// Jointly refits every number of `model` (linear block, maps, offset, initial state, block parameters).
RefitResult RefitModel(const AugmentedModel& model, const Segment& data, const RefitOptions& options);
// Which limits of a saturation-type block are estimated (the others stay infinite).
enum class LimitSides { kAny, kUpper, kLower, kBoth };

// Adds one effect block to `base` (which may already hold one) and refits jointly; a grid over the new
// block's parameters seeds the optimiser. Returns `base` refitted without the block (extra_parameters
// 0) when no grid point is admissible.
RefitResult AddBlock(const AugmentedModel& base, Effect effect, Location location, StateVariable state_variable,
                     const Segment& data, const RefitOptions& options, LimitSides sides = LimitSides::kAny);
// Re-estimates only the initial state (and nothing else) of `model` on a recording, e.g. to compare
// fixed models on a validation recording that does not start from rest. No-op when the linear block
// has no poles or when `options.estimate_initial_state` is false.
void EstimateInitialState(AugmentedModel* model, const Segment& data, const RefitOptions& options);
// Exact least squares, for fixed poles, of the numerator, the output offset and the initial state.
// Returns false (model unchanged) for models not linear in these numbers: a non-identity output map,
// an output or a state block.
bool SolveNumerator(AugmentedModel* model, const Segment& data, const RefitOptions& options);

// For fixed poles under a polynomial input map and an identity output map (no state or output block): the
// over-parametrised Hammerstein least squares y ~ offset + sum_j sum_k theta_jk (x^k / A)_{t-d-j} (+ the
// initial state), x the input after the input blocks, split into numerator and map by its rank-one
// approximation theta ~ b c^T (c_1 = 1). False (model unchanged) for other models.
bool SolveInputMapAndNumerator(AugmentedModel* model, const Segment& data, const RefitOptions& options);

// For fixed poles under a polynomial output map, output dead bands and saturations, or both: Gauss–Newton
// on the numerator, the output offset and the initial state (the map and the blocks linearised about the
// current inner signal, `iterations` least-squares solves); keeps the iterate of lowest cost. Returns
// whether the cost dropped; false (model unchanged) for models with neither, with a state block or with
// another output block.
bool SolveNumeratorThroughOutputMap(AugmentedModel* model, const Segment& data, const RefitOptions& options,
                                    int iterations = 3);
// a_1..a_n of A(q) = prod (1 - r q^-1) over the roots r (complex roots in conjugate pairs).
std::vector<double> DenominatorFromRoots(const std::vector<std::complex<double>>& roots);
// Reflects roots of A(q) outside the unit circle inside it (keeps the model simulable).
std::vector<double> StabilisedDenominator(const std::vector<double>& a);

// Least squares ARX on (x, y): y_t = -sum a_i y_{t-i} + sum b_j x_{t-d-j} (+ c when with_constant).
bool FitArx(const std::vector<double>& x, const std::vector<double>& y, int na, int nb, int d, std::size_t skip,
            std::size_t end, bool with_constant, std::vector<double>* a, std::vector<double>* b, double* constant);

// Whether the polynomial static maps are monotone over the signals they see for input u (the input map
// over the range of u after the input blocks, the output map over the simulated z's range). Identity maps
// are monotone.
bool MapsMonotone(const AugmentedModel& m, const std::vector<double>& u);

// Number of effect parameters of the blocks that are estimated (finite).
int EffectParameterCount(const AugmentedModel& m);

}  // namespace hw::diagnose
