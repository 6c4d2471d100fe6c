#pragma once
// The dynamic-horizon outer set D^ss(n) of paper 001 (Cerone, Piga, Regruto), split into sign orthants.
//
// Model (paper eqs. 1-4):  x_t = sum_i gamma_i psi_i(u_t)  (gamma_1 = 1),
//                          z_t = -sum_{i=1..na} a_i z_{t-i} + sum_{j=j0..nb} b_j x_{t-j},
//                          z_t = sum_j alpha_j phi_j(w_t)  (alpha_1 = 1),   y_t = w_t + eta_t, |eta_t| <= dy_t.
//
// Consistent reading of the nested substitution (the paper's companion matrix (14) has +a_i in its first
// row, which contradicts eq. 3; we use the matrix of eq. 3):
//   A = [ -a_1 ... -a_na ; I 0 ],  Z_t = (z_t, ..., z_{t-na+1}),  Z_t = A Z_{t-1} + e_1 v_t,  v_t = sum_j b_j x_{t-j},
//   so for horizon s = 1..n:   z_t + sum_h Q_{s,h} z_{t-s-h+1} = sum_{k=1..s} c_{s-k} v_{t-s+k},
//   with Q_{s,h} = -[A^s](1,h) (Q_{1,h} = a_h, as in eq. 7) and c_m = [A^m](1,1) (c_0 = 1).
// Result 1: every term  kappa * alpha_j * phi_j(y_tau - eta_tau)  (kappa = 1 or Q_{s,h}) is bounded
// independently over |eta_tau| <= dy_tau; the bound's side depends on sign(kappa * alpha_j), fixed in a
// sign orthant of q = (alpha_2..alpha_na_alpha, Q_{1,1..na}, ..., Q_{n,1..na}). Each (t, s) gives two
// polynomial inequalities of degree s + 1 in the parameters only. (The paper writes the sign vector with
// na(1+n) entries, i.e. it assumes n_alpha - 1 = na; in general it has (n_alpha - 1) + n * na entries.)
// Sign constraints are non-strict, so neighbouring orthants share boundaries.
#include <string>
#include <vector>

#include "core/polynomial.hpp"
#include "dss/basis.hpp"

namespace hw::dss {

struct HwStructure {
  std::vector<BasisFunction> input_basis;   // psi_1..psi_ngamma (gamma_1 = 1)
  std::vector<BasisFunction> output_basis;  // phi_1..phi_nalpha (alpha_1 = 1)
  int na = 2;
  int nb = 2;
  bool strictly_proper = true;  // b_0 = 0
  bool IsValid(std::string* error) const;
};

struct HwData {
  std::vector<double> u, y;
  std::vector<double> noise_bound;  // dy_t, per sample
  std::string source = "data";
  std::vector<int> lines;           // file line of each sample (CsvTable::lines); empty: none
  bool IsValid(std::string* error) const;
  // Where sample t (0-based) comes from, for messages: "rec.csv:17 (sample 12)" or "data: sample 12".
  std::string where(int t) const;
};

// The dynamic horizon n in 1..kMaxHorizon; false with the message (shared by ComputeBounds, the CLI and the
// Python module) in *error otherwise.
constexpr int kMaxHorizon = 20;
bool ValidHorizon(int horizon, std::string* error);
// The smallest relaxation order of D^ss(n) (paper 001, Remark 3): ceil((n + 1) / 2), at least 1 for the box.
int MinimalOrder(int horizon);

// A constant noise bound |eta_t| <= noise_bound: positive and finite. False with the message (shared by the CLI's
// --noise-bound and the Python module's noise_bound) in *error otherwise.
bool ValidNoiseBound(double noise_bound, std::string* error);

// One entry of the prior box: the interval (lo, hi) of the parameter `name`, or of every parameter when `name` is
// empty. The name is one of `names`; lo < hi, both finite. False with the message (shared by HwOuterSet, the CLI's
// --box and the Python module's box) in *error otherwise.
bool ValidBoxEntry(const std::string& name, double lo, double hi, const std::vector<std::string>& names,
                   std::string* error);

// The model class of paper 001's example: psi = phi = (w, w^2, w^3), na = nb = 2, strictly proper.
HwStructure CeroneExampleStructure();

// Parameter layout: [gamma_2.., alpha_2.., a_1..a_na, b_j0..b_nb].
struct ParameterLayout {
  std::vector<std::string> names;
  int gamma_begin = 0, alpha_begin = 0, a_begin = 0, b_begin = 0;
  int num_gamma = 0, num_alpha = 0;  // counts of unknown gamma / alpha (excluding the normalised first)
  int count() const { return static_cast<int>(names.size()); }
};
ParameterLayout MakeLayout(const HwStructure& s);

// An affine change of variables p = center + radius .* p~ that maps the prior box onto [-1, 1]^n.
struct Scaling {
  std::vector<double> center, radius;
  static Scaling FromBox(const std::vector<std::pair<double, double>>& box);
  std::vector<Polynomial> substitution() const;  // p_i as polynomials in p~
  double to_original(int i, double scaled) const { return center[i] + radius[i] * scaled; }
};

// One data inequality g(p~) >= 0 with its origin, for reports and working sets.
struct DataConstraint {
  Polynomial g;  // in scaled variables, normalised to max |coefficient| = 1
  int t = 0;     // sample index (0-based) of the current output
  int s = 0;     // horizon step
  bool upper = true;  // true: upper LHS bound >= RHS; false: lower LHS bound <= RHS
};

class HwOuterSet {
 public:
  HwOuterSet(HwStructure structure, HwData data, int horizon, std::vector<std::pair<double, double>> box);

  const ParameterLayout& layout() const { return layout_; }
  const Scaling& scaling() const { return scaling_; }
  int horizon() const { return horizon_; }
  int num_vars() const { return layout_.count(); }
  // Sign-vector polynomials q_k(p) in original variables, with names.
  const std::vector<Polynomial>& sign_polynomials() const { return q_; }
  const std::vector<std::string>& sign_names() const { return q_names_; }
  int num_orthants() const { return 1 << static_cast<int>(q_.size()); }
  // The sign pattern of orthant l: bit k set means q_k <= 0.
  std::vector<int> orthant_signs(int l) const;
  // Orthant containing a parameter point (ties to +).
  int orthant_of(const std::vector<double>& p) const;
  // Sign constraints sigma_k q_k(p~) >= 0 of orthant l (scaled, normalised).
  std::vector<Polynomial> sign_constraints(int l) const;
  // Data inequalities of orthant l (scaled, normalised).
  std::vector<DataConstraint> data_constraints(int l) const;
  // Box constraints 1 - p~_i^2 >= 0.
  std::vector<Polynomial> box_constraints() const;
  const std::vector<std::pair<double, double>>& box() const { return box_; }
  const HwStructure& structure() const { return structure_; }
  const HwData& data() const { return data_; }
  // The same data, model class and horizon in another box (a contracted one: same set inside it, new scaling).
  HwOuterSet WithBox(std::vector<std::pair<double, double>> box) const { return {structure_, data_, horizon_, std::move(box)}; }
  // Numerical warnings about the data found at construction: basis values spanning more magnitudes than the
  // solvers resolve, or noise bands below the resolution of a basis value, each with the scaling to use.
  const std::vector<std::string>& warnings() const { return warnings_; }
  // Evaluates the unscaled model equations' worst-case slack of a parameter point (for tests):
  // min over constraints of the constraint value at p (>= 0 iff p lies in D^ss(n) for its orthant).
  double min_slack(const std::vector<double>& p) const;
  // Every inequality of orthant l in original variables: the sign constraints sigma_k q_k(p) >= 0, then the
  // data rows (unscaled, in data_constraints(l)'s order).
  std::vector<Polynomial> orthant_inequalities(int l) const;

 private:
  struct Term {
    Polynomial coefficient;  // kappa * alpha_j in original variables
    int sign_kappa;          // index into q_ of kappa's sign (-1: kappa = 1)
    int sign_alpha;          // index into q_ of alpha_j's sign (-1: alpha_1 = 1)
    int sample;              // tau
    int basis;               // j
  };
  struct Equation {
    int t, s;
    std::vector<Term> lhs;
    Polynomial rhs;  // original variables
  };
  std::vector<DataConstraint> build(int l, bool scaled) const;
  void CheckBasisValues();  // non-finite basis values are errors; precision loss goes to warnings_

  HwStructure structure_;
  HwData data_;
  int horizon_;
  std::vector<std::pair<double, double>> box_;
  ParameterLayout layout_;
  Scaling scaling_;
  std::vector<Polynomial> scaled_vars_;
  std::vector<Polynomial> q_;
  std::vector<std::string> q_names_;
  std::vector<Equation> equations_;
  // phi ranges per sample and basis function: [min, max] over [y - dy, y + dy].
  std::vector<std::vector<std::pair<double, double>>> phi_range_;
  std::vector<std::string> warnings_;
};

}  // namespace hw::dss
