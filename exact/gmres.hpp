#pragma once
// Restarted GMRES with a right preconditioner (Saad, Iterative Methods for Sparse Linear Systems, §9.3).
//
// Why here: the interior point's Newton equations are solved through a regularised factor; the correction
// back to the unregularised equations was a stationary refinement, which converges only while every
// eigenvalue of (factor)^{-1} K lies within 1 of 1. Near the optimum of the lifted LPs some do not (the
// equality rows' proximal term against H_x near 1e-12), the refinement diverges, and each step adds the
// residual it left as dual infeasibility. GMRES with the same factor as preconditioner needs only that such
// eigenvalues be few.
#include <functional>
#include <string>

#include <Eigen/Dense>

namespace hw::exact {

struct GmresOptions {
  int krylov_dimension = 20;  // vectors kept before a restart
  int max_restarts = 2;
  double tolerance = 1e-14;   // on the residual's infinity norm
  bool IsValid(std::string* error) const;
};

struct GmresSummary {
  bool converged = false;
  int iterations = 0;          // applications of the operator inside the Krylov cycles
  double residual = 0.0;       // infinity norm of b - K x at the end (computed, not estimated)
};

using LinearMap = std::function<Eigen::VectorXd(const Eigen::VectorXd&)>;

// Improves *x (on entry: a first solution, e.g. the preconditioner applied to b) towards K x = b.
GmresSummary SolveGmres(const LinearMap& apply, const LinearMap& precondition, const Eigen::VectorXd& b,
                        const GmresOptions& options, Eigen::VectorXd* x);

}  // namespace hw::exact
