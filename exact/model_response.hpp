#pragma once
// The model's response for one parameter vector, in plain floating point (basis values at their interval
// midpoints): the input-side signal x_t, the linear block's output z_t from an initial state, the band ends
// p(alpha, L_t), p(alpha, H_t) and the monotonicity of p(alpha, .) on the data grid. Shared by the membership
// LP and the inner-hull search; nothing here is a certificate.
#include <vector>

#include "exact/lifted_lp.hpp"

namespace hw::exact {

// theta split by role, with the normalised first coefficients included: gamma[0] = alpha[0] = 1,
// a[i - 1] = a_i, b[j - j0] = b_j.
struct ModelParameters {
  std::vector<double> gamma, alpha, a, b;
};
ModelParameters DecodeTheta(const LiftedData& data, const std::vector<double>& theta);

// The number of free initial values z_0 .. z_{T0-1}: T0 = max(na, nb) (before it the recursion would need
// outputs or inputs before the record).
int InitialStateSize(const LiftedData& data);

// x_t = sum_k gamma_k psi_k(u_t).
std::vector<double> InputSignal(const LiftedData& data, const ModelParameters& m);

// z_t = initial[t] for t < T0, then z_t = -sum_i a_i z_{t-i} + sum_j b_j x_{t-j}.
std::vector<double> SimulateOutput(const LiftedData& data, const ModelParameters& m, const std::vector<double>& x,
                                   const std::vector<double>& initial);

// p(alpha, w) from the basis values phi_j(w) (midpoints).
double OutputMapValue(const std::vector<Interval>& phi, const std::vector<double>& alpha);

struct BandEnds {
  std::vector<double> lo, hi;  // p(alpha, L_t), p(alpha, H_t)
};
BandEnds ComputeBandEnds(const LiftedData& data, const ModelParameters& m);

// p(alpha, .) is nondecreasing between consecutive points of data.grid.
bool OutputMapIncreasing(const LiftedData& data, const ModelParameters& m);

// min over t of min(z_t - lo_t, hi_t - z_t): >= 0 iff z lies in every band.
double SmallestBandMargin(const BandEnds& bands, const std::vector<double>& z);

}  // namespace hw::exact
