#pragma once
// Sparse convex QP through Ipopt (interior point, MUMPS sparse LDL^T):
//   minimise 1/2 x^T H x + c^T x  subject to  row_lower <= A x <= row_upper,  var_lower <= x <= var_upper.
// H must be symmetric positive semidefinite (only its lower triangle is read). Infinite bounds: +-1e20.
#include <string>

#include <Eigen/Core>
#include <Eigen/SparseCore>

namespace hw::esmaeilani {

struct SparseQp {
  Eigen::SparseMatrix<double> H;  // n x n
  Eigen::VectorXd c;
  Eigen::SparseMatrix<double> A;  // m x n (m may be 0)
  Eigen::VectorXd row_lower, row_upper, var_lower, var_upper;
};

struct QpOptions {
  // kIpopt: interior point with sparse LDL^T (default; see docs/esmaeilani.md for the measured comparison).
  // kCgal: CGAL's exact simplex-type QP solver (Gmpzf arithmetic), a second independent backend.
  enum class Backend { kIpopt, kCgal };
  Backend backend = Backend::kIpopt;
  double tolerance = 1e-9;
  int max_iterations = 500;
  int print_level = 0;
};

struct QpSummary {
  bool solved = false;
  bool infeasible = false;  // Ipopt reported the constraints as (locally) infeasible
  std::string message;
  int iterations = 0;
  double objective = 0.0;
};

// x: on input the starting point (need not be feasible), on output the solution.
QpSummary SolveQp(const QpOptions& options, const SparseQp& qp, Eigen::VectorXd* x);
QpSummary SolveQpCgal(const QpOptions& options, const SparseQp& qp, Eigen::VectorXd* x);  // cgal_qp.cpp

}  // namespace hw::esmaeilani
