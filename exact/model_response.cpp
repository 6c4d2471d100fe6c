#include "exact/model_response.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include <fmt/format.h>

namespace hw::exact {

ModelParameters DecodeTheta(const LiftedData& data, const std::vector<double>& theta) {
  const auto& lay = data.layout;
  if (static_cast<int>(theta.size()) != lay.count())
    throw std::invalid_argument(fmt::format("theta has {} entries; the layout has {}", theta.size(), lay.count()));
  ModelParameters m;
  m.gamma.push_back(1.0);
  for (int k = 0; k < lay.num_gamma; ++k) m.gamma.push_back(theta[lay.gamma_begin + k]);
  m.alpha.push_back(1.0);
  for (int j = 0; j < lay.num_alpha; ++j) m.alpha.push_back(theta[lay.alpha_begin + j]);
  m.a.assign(theta.begin() + lay.a_begin, theta.begin() + lay.a_begin + data.structure.na);
  m.b.assign(theta.begin() + lay.b_begin, theta.end());
  return m;
}

int InitialStateSize(const LiftedData& data) { return std::max(data.structure.na, data.structure.nb); }

std::vector<double> InputSignal(const LiftedData& data, const ModelParameters& m) {
  std::vector<double> x(data.num_samples, 0.0);
  for (int t = 0; t < data.num_samples; ++t)
    for (std::size_t k = 0; k < m.gamma.size(); ++k) x[t] += m.gamma[k] * data.psi[t][k].mid();
  return x;
}

std::vector<double> SimulateOutput(const LiftedData& data, const ModelParameters& m, const std::vector<double>& x,
                                   const std::vector<double>& initial) {
  const int T0 = InitialStateSize(data), N = data.num_samples, j0 = data.first_lag();
  std::vector<double> z(N, 0.0);
  for (int t = 0; t < std::min(T0, N); ++t) z[t] = initial.at(t);
  for (int t = T0; t < N; ++t) {
    double v = 0.0;
    for (std::size_t i = 1; i <= m.a.size(); ++i) v -= m.a[i - 1] * z[t - i];
    for (std::size_t j = 0; j < m.b.size(); ++j) v += m.b[j] * x[t - j0 - static_cast<int>(j)];
    z[t] = v;
  }
  return z;
}

double OutputMapValue(const std::vector<Interval>& phi, const std::vector<double>& alpha) {
  double p = 0.0;
  for (std::size_t j = 0; j < alpha.size(); ++j) p += alpha[j] * phi[j].mid();
  return p;
}

BandEnds ComputeBandEnds(const LiftedData& data, const ModelParameters& m) {
  BandEnds b;
  b.lo.reserve(data.num_samples);
  b.hi.reserve(data.num_samples);
  for (int t = 0; t < data.num_samples; ++t) {
    b.lo.push_back(OutputMapValue(data.phi_lo[t], m.alpha));
    b.hi.push_back(OutputMapValue(data.phi_hi[t], m.alpha));
  }
  return b;
}

bool OutputMapIncreasing(const LiftedData& data, const ModelParameters& m) {
  for (std::size_t g = 0; g + 1 < data.phi_grid.size(); ++g)
    if (OutputMapValue(data.phi_grid[g + 1], m.alpha) < OutputMapValue(data.phi_grid[g], m.alpha)) return false;
  return true;
}

double SmallestBandMargin(const BandEnds& bands, const std::vector<double>& z) {
  double margin = std::numeric_limits<double>::infinity();
  for (std::size_t t = 0; t < z.size(); ++t) {
    if (!std::isfinite(z[t])) return -std::numeric_limits<double>::infinity();  // a diverging simulation
    margin = std::min({margin, z[t] - bands.lo[t], bands.hi[t] - z[t]});
  }
  return margin;
}

}  // namespace hw::exact
