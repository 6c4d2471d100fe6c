#pragma once
// Stage 2 of Brouri's method (paper 000, Section 5): G(j omega) from sine experiments through the
// backlash-inverse pre-compensator (Fig. 8), so that v = z = U sin(omega t) (Lemma 1) and in steady
// state x(t) = h(U |G| sin(omega t - phi)), phi = -arg G(j omega) (eqs. 15-18).
//
// Consistent reading of eqs. 19-37 used here. Writing g = U|G| and C_k for the complex coefficient of
// e^{j k omega t} in x (C_k = (a_k - j b_k)/2 with a_k, b_k of eq. 26), expanding sin^i gives
//   C_k = j^{-k} P_k(g) e^{-j k phi},   P_k(g) = sum_{i>=k, i-k even} c_i binom(i, (i+k)/2) g^i / 2^i.
// Only powers i >= k of the same parity feed harmonic k. For p = 5, k = 5 this is eq. 37:
// |G| = (16 s_5 / c_5)^(1/5) / U, phi = -psi_5 / 5. (The paper's eq. 35d has 3/8 where 1/2 belongs and
// its eq. 35g's b = -c_4 g^3/8 should be 0: even powers of sin have no fundamental.)
// The magnitude is taken from one harmonic k (default k = p: P_p is a single monomial, so g is unique;
// lower harmonics can be non-monotone in g when h is not invertible, as in the paper's example).
// Harmonic k fixes phi only modulo 2 pi / k; the candidate that best reproduces ALL harmonics 1..p
// is chosen, so phi is determined modulo 2 pi (the paper's single-harmonic formula silently assumes
// 0 <= phi < 2 pi / 5).
// Zero-order hold: the input is applied as a staircase, whose fundamental is the sine scaled by
// sinc(omega Ts / 2) and delayed by Ts/2. With zoh_correction the estimate refers to the continuous G.
#include <complex>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "estimators/brouri/nonlinear_stage.hpp"

namespace hw::brouri {

// Eq. 23: average of `periods` consecutive periods of `samples_per_period` samples starting at `first`.
// With three or more periods, isolated outliers (a sample far outside the noise of its phase across the
// periods, estimators/brouri/outliers.hpp) are left out of their phase's average and listed in `outliers`
// (0-based sample indices of y).
std::vector<double> PeriodicAverage(const std::vector<double>& y, std::size_t first, int samples_per_period,
                                    int periods, std::vector<std::size_t>* outliers = nullptr);

// Eq. 26 on one period of uniformly sampled data starting at phase 0 (rectangle rule: exact for
// harmonics below half the number of samples).
struct Harmonic {
  double a = 0.0, b = 0.0;  // cos and sin coefficients (26d, 26e); a_0/2 is the mean (26c)
  double s = 0.0, psi = 0.0;  // x = s_0 + sum s_k sin(k omega t + psi_k): s = hypot(a, b), psi = atan2(a, b)
};
std::vector<Harmonic> FourierCoefficients(const std::vector<double>& period, int max_harmonic);

struct FrequencyOptions {
  int harmonic = 0;           // k; 0 = the degree p of h^ (eq. 37 for p = 5)
  bool zoh_correction = true; // remove the staircase's sinc gain and half-sample delay
  bool IsValid(std::string* error) const;
};

struct FrequencyPoint {
  double omega = 0.0, amplitude = 0.0, sample_time = 0.0;
  int harmonic = 0;
  double gain = 0.0;          // |G^(j omega)| of the normalised model (G(0) = 1)
  double phase = 0.0;         // phi^ = -arg G^(j omega), wrapped to (-pi, pi] (unwrapped over a sweep)
  double fit_residual = 0.0;  // RMS misfit of harmonics 0..p relative to RMS of x^_N's harmonics
  std::vector<Harmonic> harmonics;
  std::vector<std::size_t> outliers;  // samples left out of the periodic average (0-based)
};

// One frequency from the averaged period x^_N (eq. 23) and the stage-1 estimate of h.
void EstimateFrequencyPoint(const FrequencyOptions& options, const std::vector<double>& h, double amplitude,
                            double omega, double sample_time, const std::vector<double>& averaged_period,
                            FrequencyPoint* point, Summary* summary);

// Makes phi continuous across ascending omega (adds multiples of 2 pi), starting near [0, 2 pi) at the lowest omega.
void UnwrapPhases(std::vector<FrequencyPoint>* points);

nlohmann::json ToJson(const FrequencyPoint& p);

}  // namespace hw::brouri
