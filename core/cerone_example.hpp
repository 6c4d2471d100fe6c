#pragma once
// The simulated example of paper 001 (Cerone, Piga, Regruto), Section VI:
//   x = u + 0.4 u^2 - 0.1 u^3,  z_t = -1.8 z_{t-1} - 0.9 z_{t-2} + 1.6 x_{t-1} + 2.1 x_{t-2},
//   z = w + 0.8 w^2 + 3.2 w^3 (inverse output map; strictly increasing, so w is unique),
//   u uniform in [-10, 10], y = w + eta, eta uniform in [-dy, dy], dy set for SNR_w = 31 dB.
// The paper lists theta = [a1 a2 b1 b2] = [1.8 0.9 1.6 2.1] with eq. 3's sign convention
// z_t = -a1 z_{t-1} - a2 z_{t-2} + ..., giving poles -0.9 +/- 0.3i (stable).
#include <cstdint>
#include <string>
#include <vector>

namespace hw {

struct CeroneExample {
  std::vector<double> u, w, y;
  double noise_bound = 0.0;  // dy, constant
  double snr_db = 0.0;       // realised 10 log10(sum w^2 / sum eta^2)
  // True parameters in hwbounds' layout [gamma2 gamma3 alpha2 alpha3 a1 a2 b1 b2].
  static std::vector<double> TrueParameters() { return {0.4, -0.1, 0.8, 3.2, 1.8, 0.9, 1.6, 2.1}; }
};

// dy is chosen from the noise-free output so that the expected SNR (E eta^2 = dy^2 / 3) equals snr_db.
CeroneExample SimulateCeroneExample(uint64_t seed, int samples = 1000, double snr_db = 31.0);

// Solves z = w + 0.8 w^2 + 3.2 w^3 for w (the example's output map).
double CeroneOutputMap(double z);

}  // namespace hw
