#pragma once
// The paper's pressure-control-valve case rebuilt in simulation (the plant recordings are private):
// linear block = the paper's identified a, b, d (observable canonical form, eq. 4 / Section 4.2),
// Hammerstein function with a dead band at the top of the command range (Fig. 6a: no response from
// 100 % down to 80 %), Wiener function with hard saturation near 0 % and 100 % (Fig. 6b), output
// measurement noise, closing operations that start from the fully open steady state.
#include <vector>

#include "estimators/esmaeilani/estimator.hpp"

namespace hw::esmaeilani {

struct ValveCase {
  // Paper Section 4.2 (paper order a = [a_3 a_2 a_1]).
  std::vector<double> a = {-0.0009, 0.7650, -1.7484};
  std::vector<double> b = {0.7959, -1.7600, 0.9884};
  double d = 0.0;
  double dead_band_start = 80.0;  // f(u) = min(u, 80): command above 80 % does not move the valve
  double g_offset = 4.0, g_gain = 1.15;  // g(z) = clamp((z - 4) / 1.15, 0, 100)
  double output_noise_std = 0.3;  // % of range
  double input_noise_std = 0.05;

  double f(double u) const;
  double g(double z) const;
  double g_inverse(double y) const;  // on the unsaturated part
  EsmaeilaniModel TrueModel(int grid) const;  // the true system as an EsmaeilaniModel (for simulation)
  // One closing operation of `samples` samples: command 100 % (fully open steady state), then closed
  // towards two random levels with slow random variation. Returns noisy u, y; w is the noise-free output.
  Segment ClosingOperation(unsigned seed, int samples, std::vector<double>* w = nullptr) const;
  // The constraints an engineer would state for this valve (paper Section 4.2 iv): ranges, slope
  // limits, d = 0, and the calibrated mid-range of the command f(0) = 0, f(50) = 50.
  Constraints KnownInformation() const;
};

}  // namespace hw::esmaeilani
