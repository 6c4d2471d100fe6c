#pragma once
// The lifted LP relaxation of the exact feasible set D over a parameter box (paper 001, eqs. 8-11).
//
// D is the set of theta = (gamma, alpha, a, b) for which one noise sequence |eta_t| <= dy_t makes the model
// hold on the whole record. With z_t the linear block's output (a variable per sample, the first na free:
// the initial state), beta_jk = b_j gamma_k (input-side over-parametrisation) and the model-class assumption
// that the inverse output map p(alpha, w) = sum_j alpha_j phi_j(w) increases on the data range,
//   z_t + sum_i a_i z_{t-i} - sum_j sum_k beta_jk psi_k(u_{t-j}) = 0          (t with all lags in the window)
//   p(alpha, y_t - dy_t) <= z_t <= p(alpha, y_t + dy_t)                         (every t)
//   p(alpha, g_{m+1}) >= p(alpha, g_m)                                          (a grid of the data range).
// The only nonconvex terms are the products w_it = a_i z_{t-i} (and c_ij = a_i alpha_j, beta_jk = b_j gamma_k).
// Over a box a_i in [l, u] each product gets the four products of the box factors (a_i - l, u - a_i) with the
// band factors (z - p(alpha, L), p(alpha, H) - z), linear in (w, z, a, alpha, c) — tighter than constant z
// bounds because the band moves with alpha — and McCormick envelopes for c and beta. Every column gets a
// finite a-priori bound from interval arithmetic over the box (the certificate needs them).
//
// Rows and columns depend on the window and the structure only, not on the box, so a child box's LP has its
// parent's shape and starts from its basis. The equations carry a slack s: |residual_t| <= s. In the
// feasibility form s is free in [0, S] and minimised (a rigorous lower bound > 0 proves the box empty); in the
// bounding form s is fixed to 0 and the objective is a parameter.
#include <string>
#include <vector>

#include "dss/hw_outer_set.hpp"
#include "exact/parameter_forms.hpp"
#include "exact/interval.hpp"
#include "exact/lp_problem.hpp"

namespace hw::exact {

// The data of one run, evaluated once: band ends and basis values as intervals that contain the exact ones.
struct LiftedData {
  dss::HwStructure structure;
  dss::ParameterLayout layout;
  int num_samples = 0;
  std::vector<double> band_lo, band_hi;             // L_t = y_t - dy_t rounded down, H_t = y_t + dy_t rounded up
  std::vector<std::vector<Interval>> phi_lo, phi_hi; // [t][j]: phi_j(L_t), phi_j(H_t)
  std::vector<std::vector<Interval>> psi;            // [t][k]: psi_k(u_t)
  std::vector<std::vector<Interval>> phi_grid;       // [m][j]: phi_j at the monotonicity grid's points
  std::vector<double> grid;                          // the grid over [min L_t, max H_t]
  std::vector<ParameterForm> forms;                  // extra factors of the products (exact/parameter_forms.hpp)
  int first_lag() const { return structure.strictly_proper ? 1 : 0; }
};
// Checks the structure and data (throws hw::InputError with the sample's place for a non-finite value).
LiftedData MakeLiftedData(const dss::HwStructure& structure, const dss::HwData& data, int grid_points = 64);

// A box of the parameters in the layout's order [gamma_2.., alpha_2.., a_1..a_na, b_j0..b_nb], then (optional)
// the ranges of data.forms (exact/parameter_forms.hpp).

struct Window {
  int begin = 0, end = 0;  // samples [begin, end)
  bool operator==(const Window& o) const { return begin == o.begin && end == o.end; }
};

enum class LiftedForm { kFeasibility, kBounding };

// The LP and where its columns are. Objectives are set by the caller (SetObjective).
struct LiftedLp {
  LpProblem lp;
  Window window;
  int s_col = -1;
  std::vector<int> param_col;   // per box entry (gamma_k, alpha_j, a_i, b_j = beta_j1, then the forms)
  std::vector<int> z_col;       // per sample of the window (index t - window.begin)
  int num_equations = 0;
  // Sets the objective to minimise sum_k weight_k * parameter_k (0 elsewhere); the feasibility form minimises s.
  void SetParameterObjective(const std::vector<double>& weights);
  void SetSlackObjective();
  // Objective over the beta columns too: minimise sum_j w_j (beta_{j,k} - g * beta_{j,1}) over the terms
  // (j_index, w_j) (a Dinkelbach step for gamma_k).
  void SetRatioObjective(const std::vector<std::pair<int, double>>& terms, int k, double g);
  std::vector<std::vector<int>> beta_col;  // [j - j0][k]: beta_jk; k = 0 is b_j itself
};

LiftedLp BuildLiftedLp(const LiftedData& data, const ParamBox& box, Window window, LiftedForm form);

}  // namespace hw::exact
