#include "exact/gmres.hpp"

#include <cmath>
#include <string>
#include <vector>

namespace hw::exact {

bool GmresOptions::IsValid(std::string* error) const {
  if (krylov_dimension < 1 || max_restarts < 1 || !(tolerance >= 0.0)) {
    if (error) *error = "GMRES needs krylov_dimension >= 1, max_restarts >= 1 and tolerance >= 0";
    return false;
  }
  return true;
}

namespace {

using Eigen::VectorXd;

// Plane rotation (c, s) that zeroes b in (a, b).
void Rotation(double a, double b, double* c, double* s) {
  const double r = std::hypot(a, b);
  *c = r > 0 ? a / r : 1.0;
  *s = r > 0 ? b / r : 0.0;
}

// One cycle of right-preconditioned GMRES from *x; returns the operator applications spent.
int Cycle(const LinearMap& apply, const LinearMap& precondition, const VectorXd& r0, int k_max, double tolerance,
          VectorXd* x) {
  const double beta = r0.norm();
  std::vector<VectorXd> basis{r0 / beta}, directions;
  Eigen::MatrixXd h = Eigen::MatrixXd::Zero(k_max + 1, k_max);
  VectorXd c = VectorXd::Zero(k_max), s = VectorXd::Zero(k_max), g = VectorXd::Zero(k_max + 1);
  g[0] = beta;
  int k = 0;
  while (k < k_max) {
    directions.push_back(precondition(basis[k]));
    VectorXd w = apply(directions[k]);
    for (int i = 0; i <= k; ++i) {  // modified Gram-Schmidt
      h(i, k) = w.dot(basis[i]);
      w -= h(i, k) * basis[i];
    }
    const double w_norm = w.norm();
    h(k + 1, k) = w_norm;
    for (int i = 0; i < k; ++i) {
      const double t = c[i] * h(i, k) + s[i] * h(i + 1, k);
      h(i + 1, k) = -s[i] * h(i, k) + c[i] * h(i + 1, k);
      h(i, k) = t;
    }
    Rotation(h(k, k), h(k + 1, k), &c[k], &s[k]);
    h(k, k) = c[k] * h(k, k) + s[k] * h(k + 1, k);
    h(k + 1, k) = 0.0;
    g[k + 1] = -s[k] * g[k];
    g[k] = c[k] * g[k];
    ++k;
    // The 2-norm estimate bounds the infinity norm; stop early once it is far below the tolerance.
    if (std::abs(g[k]) <= 1e-2 * tolerance || w_norm == 0.0) break;
    basis.push_back(w / w_norm);
  }
  VectorXd y = VectorXd::Zero(k);
  for (int i = k - 1; i >= 0; --i) {
    double sum = g[i];
    for (int j = i + 1; j < k; ++j) sum -= h(i, j) * y[j];
    y[i] = h(i, i) != 0.0 ? sum / h(i, i) : 0.0;
  }
  for (int i = 0; i < k; ++i) *x += y[i] * directions[i];
  return k;
}

}  // namespace

GmresSummary SolveGmres(const LinearMap& apply, const LinearMap& precondition, const VectorXd& b,
                        const GmresOptions& options, VectorXd* x) {
  GmresSummary summary;
  for (int restart = 0;; ++restart) {
    const VectorXd r = b - apply(*x);
    summary.residual = r.lpNorm<Eigen::Infinity>();
    if (!std::isfinite(summary.residual)) return summary;
    if (summary.residual <= options.tolerance) {
      summary.converged = true;
      return summary;
    }
    if (restart == options.max_restarts) return summary;
    summary.iterations += Cycle(apply, precondition, r, options.krylov_dimension, options.tolerance, x);
  }
}

}  // namespace hw::exact
