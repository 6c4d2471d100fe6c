// The same sparse convex QP through CGAL's exact QP solver (CGAL::solve_quadratic_program, Gmpzf
// arithmetic), as a second, independent backend for the per-iteration QP (QpOptions::backend).
// CGAL minimises x^T D x + c^T x; its set_d(i, j, v) sets 2D_ij, so it receives H itself.
#include <CGAL/Gmpzf.h>
#include <CGAL/QP_functions.h>
#include <CGAL/QP_models.h>

#include <fmt/format.h>

#include "estimators/esmaeilani/sparse_qp.hpp"

namespace hw::esmaeilani {

QpSummary SolveQpCgal(const QpOptions&, const SparseQp& qp, Eigen::VectorXd* x) {
  constexpr double kInf = 1e19;  // bounds at or beyond +-1e19 count as infinite (Ipopt's convention)
  QpSummary summary;
  const int n = static_cast<int>(qp.c.size());
  // No default bounds: every variable is free unless set below.
  CGAL::Quadratic_program<double> p(CGAL::SMALLER, false, 0.0, false, 0.0);
  for (int j = 0; j < n; ++j) {
    if (qp.var_lower[j] > -kInf) p.set_l(j, true, qp.var_lower[j]);
    if (qp.var_upper[j] < kInf) p.set_u(j, true, qp.var_upper[j]);
    p.set_c(j, qp.c[j]);
  }
  for (int k = 0; k < qp.H.outerSize(); ++k)
    for (Eigen::SparseMatrix<double>::InnerIterator it(qp.H, k); it; ++it)
      if (it.row() >= it.col() && it.value() != 0.0) p.set_d(static_cast<int>(it.row()), static_cast<int>(it.col()), it.value());
  // Two-sided rows become up to two one-sided rows (equal bounds: one equality row).
  const Eigen::SparseMatrix<double, Eigen::RowMajor> A = qp.A;
  int row = 0;
  for (int i = 0; i < A.rows(); ++i) {
    const double lo = qp.row_lower[i], hi = qp.row_upper[i];
    auto add_row = [&](CGAL::Comparison_result rel, double rhs) {
      for (Eigen::SparseMatrix<double, Eigen::RowMajor>::InnerIterator it(A, i); it; ++it)
        p.set_a(static_cast<int>(it.col()), row, it.value());
      p.set_r(row, rel);
      p.set_b(row, rhs);
      ++row;
    };
    if (lo > -kInf && hi < kInf && lo == hi) {
      add_row(CGAL::EQUAL, lo);
    } else {
      if (lo > -kInf) add_row(CGAL::LARGER, lo);
      if (hi < kInf) add_row(CGAL::SMALLER, hi);
    }
  }
  const auto s = CGAL::solve_quadratic_program(p, CGAL::Gmpzf());
  summary.iterations = s.number_of_iterations();
  if (s.is_infeasible()) {
    summary.infeasible = true;
    summary.message = "CGAL: infeasible";
    return summary;
  }
  if (!s.is_optimal()) {
    summary.message = s.is_unbounded() ? "CGAL: unbounded" : "CGAL: no optimal solution";
    return summary;
  }
  x->resize(n);
  int j = 0;
  for (auto it = s.variable_values_begin(); it != s.variable_values_end(); ++it, ++j) (*x)[j] = CGAL::to_double(*it);
  summary.objective = CGAL::to_double(s.objective_value());
  summary.solved = true;
  summary.message = "CGAL: optimal";
  return summary;
}

}  // namespace hw::esmaeilani
