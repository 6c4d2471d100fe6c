#include "exact/membership.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "exact/model_response.hpp"

namespace hw::exact {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// z_t = offset_t + sum_k coef[k][t] * z_k for the free initial values z_0 .. z_{T0-1}: the recursion run once
// with the input and a zero initial state, and once per unit initial value with a zero input.
struct AffineOutput {
  std::vector<double> offset;
  std::vector<std::vector<double>> coef;
  bool finite() const {
    auto ok = [](const std::vector<double>& v) {
      return std::all_of(v.begin(), v.end(), [](double e) { return std::isfinite(e); });
    };
    return ok(offset) && std::all_of(coef.begin(), coef.end(), ok);
  }
};

AffineOutput MakeAffineOutput(const LiftedData& data, const ModelParameters& m, const std::vector<double>& x) {
  const int T0 = InitialStateSize(data);
  AffineOutput out;
  out.offset = SimulateOutput(data, m, x, std::vector<double>(T0, 0.0));
  const std::vector<double> no_input(x.size(), 0.0);
  for (int k = 0; k < T0; ++k) {
    std::vector<double> unit(T0, 0.0);
    unit[k] = 1.0;
    out.coef.push_back(SimulateOutput(data, m, no_input, unit));
  }
  return out;
}

// max s subject to lo_t + s <= z_t <= hi_t - s. Every column needs finite bounds: the initial values may leave
// their bands by R (an optimum with s < -R is negative however R is chosen, so the sign of s is exact), and
// s >= -S with S larger than any violation a point of that box can have, so the LP is always feasible.
LpProblem MembershipLp(const AffineOutput& f, const BandEnds& bands) {
  const int T0 = static_cast<int>(f.coef.size());
  const int N = static_cast<int>(f.offset.size());
  double band_scale = 0.0;
  for (int t = 0; t < N; ++t) band_scale = std::max({band_scale, std::abs(bands.lo[t]), std::abs(bands.hi[t])});
  const double R = 10.0 * (1.0 + band_scale);
  LpProblem lp;
  std::vector<double> z_abs(T0);
  for (int k = 0; k < T0; ++k) {
    lp.AddColumn(bands.lo[k] - R, bands.hi[k] + R);
    z_abs[k] = std::max(std::abs(lp.col_lo[k]), std::abs(lp.col_hi[k]));
  }
  double S = 0.0;
  for (int t = 0; t < N; ++t) {
    double reach = std::abs(f.offset[t]) + std::max(std::abs(bands.lo[t]), std::abs(bands.hi[t]));
    for (int k = 0; k < T0; ++k) reach += std::abs(f.coef[k][t]) * z_abs[k];
    S = std::max(S, reach);
  }
  const int s = lp.AddColumn(-(S + 1.0), 0.5 * band_scale + 1.0);
  lp.obj[s] = -1.0;
  for (int t = 0; t < N; ++t) {
    const int lower = lp.AddRow(bands.lo[t] - f.offset[t], kInf);   // z_t - s >= lo_t
    const int upper = lp.AddRow(-kInf, bands.hi[t] - f.offset[t]);  // z_t + s <= hi_t
    for (int k = 0; k < T0; ++k) {
      if (f.coef[k][t] == 0.0) continue;
      lp.AddEntry(lower, k, f.coef[k][t]);
      lp.AddEntry(upper, k, f.coef[k][t]);
    }
    lp.AddEntry(lower, s, -1.0);
    lp.AddEntry(upper, s, 1.0);
  }
  return lp;
}

}  // namespace

MembershipResult CheckMembership(const LiftedData& data, const std::vector<double>& theta, LpSolver& solver) {
  const ModelParameters m = DecodeTheta(data, theta);
  const int T0 = InitialStateSize(data);
  MembershipResult result;
  result.slack = -kInf;
  result.increasing = OutputMapIncreasing(data, m);
  const std::vector<double> x = InputSignal(data, m);
  const BandEnds bands = ComputeBandEnds(data, m);
  const AffineOutput f = MakeAffineOutput(data, m, x);
  if (!f.finite() || data.num_samples < T0) return result;  // a diverging response is in no band
  const LpResult lp = solver.Solve(MembershipLp(f, bands), LpBasis{}, LpSolveOptions{});
  if (lp.status != LpStatus::kOptimal || static_cast<int>(lp.primal.size()) < T0) return result;
  // The slack is what the LP's initial state attains when simulated, not the LP's own value.
  result.initial_state.assign(lp.primal.begin(), lp.primal.begin() + T0);
  result.slack = SmallestBandMargin(bands, SimulateOutput(data, m, x, result.initial_state));
  result.member = result.slack >= 0.0 && result.increasing;
  return result;
}

}  // namespace hw::exact
