// Restarted, right-preconditioned GMRES (exact/gmres.hpp): it converges where a stationary refinement with the
// same preconditioner diverges, which is why the interior point's Newton solves use it.
#include <gtest/gtest.h>

#include <random>

#include "exact/gmres.hpp"

namespace hw::exact {
namespace {

using Eigen::MatrixXd;
using Eigen::VectorXd;

// K = D + a small coupling; the preconditioner inverts D exactly except on a few entries, where it is three
// times too large.
struct Problem {
  MatrixXd k;
  VectorXd preconditioner_diagonal;  // P^{-1} = diag(this)
  VectorXd b;
};

Problem MakeProblem(int n, int far_entries, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  Problem p;
  p.k = MatrixXd::Zero(n, n);
  p.preconditioner_diagonal.resize(n);
  p.b.resize(n);
  for (int i = 0; i < n; ++i) {
    const double d = 2.0 + unit(rng);
    p.k(i, i) = d;
    // On the first `far_entries` the preconditioner is 3 times the inverse: eigenvalues near 3, where a
    // stationary refinement's error factor 1 - 3 = -2 doubles the error every pass.
    p.preconditioner_diagonal[i] = (i < far_entries ? 3.0 : 1.0) / d;
    p.b[i] = unit(rng);
  }
  for (int i = 0; i + 1 < n; ++i) p.k(i, i + 1) = p.k(i + 1, i) = 1e-3 * unit(rng);
  return p;
}

TEST(Gmres, ConvergesWhereStationaryRefinementDiverges) {
  const Problem p = MakeProblem(200, 3, 7);
  const LinearMap apply = [&](const VectorXd& x) -> VectorXd { return p.k * x; };
  const LinearMap precondition = [&](const VectorXd& r) -> VectorXd { return p.preconditioner_diagonal.cwiseProduct(r); };

  VectorXd stationary = precondition(p.b);
  const double first = (p.b - apply(stationary)).lpNorm<Eigen::Infinity>();
  for (int pass = 0; pass < 10; ++pass) stationary += precondition(p.b - apply(stationary));
  EXPECT_GT((p.b - apply(stationary)).lpNorm<Eigen::Infinity>(), 100.0 * first);  // the trap GMRES avoids

  VectorXd x = precondition(p.b);
  GmresOptions options;
  options.tolerance = 1e-12;
  const GmresSummary summary = SolveGmres(apply, precondition, p.b, options, &x);
  EXPECT_TRUE(summary.converged);
  EXPECT_LE(summary.residual, 1e-12);
  EXPECT_LE((p.b - p.k * x).lpNorm<Eigen::Infinity>(), 1e-12);
  EXPECT_LE(summary.iterations, 20);
}

TEST(Gmres, ReportsWhenItDoesNotConverge) {
  const Problem p = MakeProblem(200, 200, 11);
  const LinearMap apply = [&](const VectorXd& x) -> VectorXd { return p.k * x; };
  const LinearMap identity = [](const VectorXd& r) -> VectorXd { return r; };
  // Without a preconditioner and two Krylov vectors, 1e-15 is out of reach: the summary says so and keeps the
  // computed residual.
  VectorXd x = VectorXd::Zero(p.b.size());
  GmresOptions options;
  options.krylov_dimension = 2;
  options.max_restarts = 1;
  options.tolerance = 1e-15;
  const GmresSummary summary = SolveGmres(apply, identity, p.b, options, &x);
  EXPECT_FALSE(summary.converged);
  EXPECT_NEAR(summary.residual, (p.b - p.k * x).lpNorm<Eigen::Infinity>(), 1e-15);
  EXPECT_GT(summary.residual, 1e-15);
}

TEST(Gmres, OptionsAreValidated) {
  std::string error;
  EXPECT_TRUE(GmresOptions{}.IsValid(&error));
  GmresOptions bad;
  bad.krylov_dimension = 0;
  EXPECT_FALSE(bad.IsValid(&error));
  EXPECT_NE(error.find("krylov_dimension"), std::string::npos);
}

}  // namespace
}  // namespace hw::exact
