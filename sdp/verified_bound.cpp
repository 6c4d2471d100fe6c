#include "sdp/verified_bound.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

#include <CGAL/Interval_nt.h>
#include <Eigen/Sparse>
#include <fmt/format.h>

namespace hw::sdp {
namespace {

// Interval arithmetic with directed rounding. Interval_nt_advanced needs the FPU in round-upward mode, which
// a CGAL::Protect_FPU_rounding<true> object sets for its scope (and restores after). CGAL stops the compiler
// from folding or moving operations across the mode change; this file is also built with -frounding-math.
// Nothing but interval operations may run inside such a scope (Eigen's eigen-solver runs outside).
using I = CGAL::Interval_nt_advanced;
using Protect = CGAL::Protect_FPU_rounding<true>;
using Clock = std::chrono::steady_clock;
constexpr double kInf = std::numeric_limits<double>::infinity();

double magnitude(const I& x) { return std::max(std::abs(x.inf()), std::abs(x.sup())); }

// Upper bound of sqrt(sum of squares) of the interval entries of a symmetric matrix given by its upper triangle
// (computed inside a Protect scope, so double + and * round upward).
struct FrobeniusUp {
  double sum = 0.0;
  void add(const I& x, bool off_diagonal) {
    const double m = magnitude(x);
    sum += (off_diagonal ? 2.0 : 1.0) * (m * m);
  }
  double value() const { return CGAL::sqrt(I(sum)).sup(); }
};

// F . X over the upper-triangle entries (off-diagonal entries count twice), enclosed.
I inner(const std::vector<Entry>& F, const std::vector<Eigen::MatrixXd>& X) {
  I s(0.0);
  for (const auto& e : F) s += I(e.value) * I(X[e.block](e.row, e.col)) * I(e.row == e.col ? 1.0 : 2.0);
  return s;
}

// Shared core of VerifyLowerBound (use_objective) and VerifyInfeasibility (c = 0 and no offset).
VerifiedBound Verify(const LmiProblem& problem, const std::vector<Eigen::MatrixXd>& X, const VariableBounds& bounds,
                     bool use_objective) {
  const auto t0 = Clock::now();
  VerifiedBound out;
  out.status = VerifyStatus::kUnverified;
  out.bound = -kInf;
  auto done = [&](std::string message) {
    out.message = std::move(message);
    out.seconds = std::chrono::duration<double>(Clock::now() - t0).count();
    return out;
  };
  std::string error;
  if (!problem.IsValid(&error)) return done("invalid problem: " + error);
  const int m = problem.num_vars();
  const int nb = static_cast<int>(problem.blocks.size());
  if (static_cast<int>(X.size()) != nb) return done(fmt::format("no multiplier to verify ({} blocks of {})", X.size(), nb));
  for (int b = 0; b < nb; ++b) {
    if (X[b].rows() != problem.blocks[b].size || X[b].cols() != problem.blocks[b].size)
      return done(fmt::format("multiplier block {} is {}x{}, expected {}", b, X[b].rows(), X[b].cols(),
                              problem.blocks[b].size));
    if (!X[b].allFinite()) return done(fmt::format("multiplier block {} is not finite", b));
  }
  if (static_cast<int>(bounds.lower.size()) != m || static_cast<int>(bounds.upper.size()) != m)
    return done("a-priori variable bounds missing");

  // Rigorous lower bounds of lambda_min per block (outside the Protect scope: uses Eigen's eigen-solver).
  std::vector<double> lambda(nb);
  for (int b = 0; b < nb; ++b) {
    if (problem.blocks[b].kind == BlockSpec::Kind::kDiagonal)
      lambda[b] = X[b].diagonal().minCoeff();  // exact
    else
      lambda[b] = MinEigenvalueLowerBound(X[b]);
    if (!(lambda[b] > -kInf)) return done(fmt::format("no eigenvalue bound for multiplier block {}", b));
  }
  out.min_eigenvalue = *std::min_element(lambda.begin(), lambda.end());

  Protect protect;
  // Enclosures of F_0 . X, of r_i = c_i - F_i . X, and of the block traces of F_i (for T_j).
  const I f0x = inner(problem.F[0], X);
  std::vector<I> tr0(nb, I(0.0));
  for (const auto& e : problem.F[0])
    if (e.row == e.col) tr0[e.block] += I(e.value);
  std::vector<I> T(nb, I(0.0));  // T_j: enclosure of max over the box of tr F_j(y) (sup is what is used)
  for (int b = 0; b < nb; ++b) T[b] = -tr0[b];
  I residual_term(0.0);
  bool unbounded_residual = false, unbounded_trace = false;
  int first_unbounded = -1;
  std::vector<I> tri(nb, I(0.0));
  for (int i = 1; i <= m; ++i) {
    const double lo = bounds.lower[i - 1], hi = bounds.upper[i - 1];
    const bool finite = std::isfinite(lo) && std::isfinite(hi) && lo <= hi;
    const I box = finite ? I(lo, hi) : I(0.0);
    const I r = I(use_objective ? problem.c[i - 1] : 0.0) - inner(problem.F[i], X);
    if (!(r.inf() == 0.0 && r.sup() == 0.0)) {
      if (!finite) {
        unbounded_residual = true;
        if (first_unbounded < 0) first_unbounded = i;
      } else {
        residual_term += r * box;
      }
    }
    std::fill(tri.begin(), tri.end(), I(0.0));
    bool any = false;
    for (const auto& e : problem.F[i])
      if (e.row == e.col) {
        tri[e.block] += I(e.value);
        any = true;
      }
    if (!any) continue;
    for (int b = 0; b < nb; ++b) {
      if (tri[b].inf() == 0.0 && tri[b].sup() == 0.0) continue;
      if (!finite) {
        if (lambda[b] < 0.0) unbounded_trace = true;
        continue;
      }
      T[b] += tri[b] * box;
    }
  }
  if (unbounded_residual)
    return done(fmt::format("variable {} has a nonzero residual and no a-priori bound", first_unbounded));
  if (unbounded_trace) return done("a block with a negative multiplier eigenvalue has no a-priori trace bound");
  I eigen_term(0.0);
  for (int b = 0; b < nb; ++b) {
    if (lambda[b] >= 0.0) continue;
    const double t = std::max(0.0, T[b].sup());  // tr F_j(y) >= 0 on the feasible set anyway
    eigen_term += I(lambda[b]) * I(t);
  }
  const I offset(use_objective ? problem.objective_offset : 0.0);
  const I total = f0x + offset + residual_term + eigen_term;
  out.residual_term = residual_term.inf();
  out.eigenvalue_term = eigen_term.inf();
  out.bound = total.inf();
  if (!std::isfinite(out.bound)) {
    out.bound = -kInf;
    return done("the enclosure overflowed");
  }
  out.status = VerifyStatus::kVerified;
  return done("");
}

// Least-squares repair of the equalities F_i . X = c_i (floating point; the result is verified like any X):
// X + sum_k mu_k F_k with G mu = r, G_ik = F_i . F_k, the smallest change in the trace norm. Interior-point
// multipliers are safely inside the cone, so the tiny change keeps them PSD while the residuals (which the
// a-priori bounds multiply) drop to rounding level. Empty on failure.
std::vector<Eigen::MatrixXd> ProjectOntoEqualities(const LmiProblem& problem, const std::vector<Eigen::MatrixXd>& X) {
  const int m = problem.num_vars();
  const int nb = static_cast<int>(problem.blocks.size());
  std::vector<long> offset(nb + 1, 0);
  for (int b = 0; b < nb; ++b) offset[b + 1] = offset[b] + static_cast<long>(problem.blocks[b].size) * problem.blocks[b].size;
  std::vector<Eigen::Triplet<double>> t;
  t.reserve(problem.nonzeros());
  Eigen::VectorXd r(m);
  for (int i = 1; i <= m; ++i) {
    double fx = 0.0;
    for (const auto& e : problem.F[i]) {
      const double w = e.row == e.col ? 1.0 : 2.0;
      fx += w * e.value * X[e.block](e.row, e.col);
      t.emplace_back(i - 1, offset[e.block] + static_cast<long>(e.row) * problem.blocks[e.block].size + e.col,
                     std::sqrt(w) * e.value);
    }
    r[i - 1] = problem.c[i - 1] - fx;
  }
  Eigen::SparseMatrix<double> A(m, offset[nb]);
  A.setFromTriplets(t.begin(), t.end());
  Eigen::SparseMatrix<double> G = A * A.transpose();
  double top = 0.0;
  for (int i = 0; i < m; ++i) top = std::max(top, G.coeff(i, i));
  if (!(top > 0)) return {};
  for (int i = 0; i < m; ++i) G.coeffRef(i, i) += 1e-14 * top;  // variables without F_i stay solvable
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt(G);
  if (ldlt.info() != Eigen::Success) return {};
  const Eigen::VectorXd mu = ldlt.solve(r);
  if (ldlt.info() != Eigen::Success || !mu.allFinite()) return {};
  std::vector<Eigen::MatrixXd> out = X;
  for (int i = 1; i <= m; ++i)
    for (const auto& e : problem.F[i]) {
      out[e.block](e.row, e.col) += mu[i - 1] * e.value;
      if (e.row != e.col) out[e.block](e.col, e.row) += mu[i - 1] * e.value;
    }
  return out;
}

double max_abs(const std::vector<Eigen::MatrixXd>& X) {
  double s = 0.0;
  for (const auto& B : X)
    if (B.size()) s = std::max(s, B.cwiseAbs().maxCoeff());
  return s;
}

}  // namespace

bool VerifyOptions::IsValid(std::string* error) const {
  auto fail = [&](std::string m) {
    if (error) *error = std::move(m);
    return false;
  };
  if (!(acceptable_correction >= 0)) return fail("acceptable_correction must be >= 0");
  if (max_resolves < 0) return fail("max_resolves must be >= 0");
  if (!(perturbation > 0 && perturbation < 1)) return fail("perturbation must lie in (0, 1)");
  return true;
}

std::string ToString(VerifyStatus s) {
  switch (s) {
    case VerifyStatus::kNotRun: return "off";
    case VerifyStatus::kVerified: return "verified";
    case VerifyStatus::kUnverified: return "unverified";
  }
  return "unknown";
}

nlohmann::json VerifiedBound::to_json() const {
  auto num = [](double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); };
  return {{"status", ToString(status)}, {"message", message}, {"bound", num(bound)}, {"float_bound", num(float_bound)},
          {"correction", num(correction)}, {"residual_term", num(residual_term)},
          {"eigenvalue_term", num(eigenvalue_term)}, {"min_eigenvalue", num(min_eigenvalue)},
          {"resolves", resolves}, {"seconds", seconds}, {"resolve_seconds", resolve_seconds}};
}

double MinEigenvalueLowerBound(const Eigen::MatrixXd& A) {
  const Eigen::Index n = A.rows();
  if (n == 0 || A.cols() != n || !A.allFinite()) return -kInf;
  const Eigen::MatrixXd S = A.selfadjointView<Eigen::Upper>();
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(S);
  if (es.info() != Eigen::Success) return -kInf;
  const Eigen::VectorXd& d = es.eigenvalues();
  const Eigen::MatrixXd& V = es.eigenvectors();
  if (!d.allFinite() || !V.allFinite()) return -kInf;
  const double dmin = d.minCoeff();
  Protect protect;
  // W = V D (enclosed), then E = S - W V^T and G = V^T V - I, both by Frobenius norms from above.
  std::vector<I> W(static_cast<std::size_t>(n * n));
  for (Eigen::Index k = 0; k < n; ++k)
    for (Eigen::Index r = 0; r < n; ++r) W[k * n + r] = I(V(r, k)) * I(d(k));
  FrobeniusUp e, g;
  for (Eigen::Index c = 0; c < n; ++c) {
    for (Eigen::Index r = 0; r <= c; ++r) {
      I acc(S(r, c));
      I gram(r == c ? -1.0 : 0.0);
      for (Eigen::Index k = 0; k < n; ++k) {
        acc -= W[k * n + r] * I(V(c, k));
        gram += I(V(k, r)) * I(V(k, c));
      }
      e.add(acc, r != c);
      g.add(gram, r != c);
    }
  }
  const double normE = e.value(), eta = g.value();
  // x^T V D V^T x >= d_min ||V^T x||^2 and 1 - eta <= ||V^T x||^2 <= 1 + eta for unit x.
  if (dmin >= 0.0 && !(eta < 1.0)) return -normE;  // only 0 <= x^T V D V^T x is known
  const I scale = dmin >= 0.0 ? I(1.0) - I(eta) : I(1.0) + I(eta);
  const double lb = (I(dmin) * scale - I(normE)).inf();
  return std::isfinite(lb) ? lb : -kInf;
}

VerifiedBound VerifyLowerBound(const LmiProblem& problem, const std::vector<Eigen::MatrixXd>& X,
                               const VariableBounds& bounds, double float_bound) {
  VerifiedBound v = Verify(problem, X, bounds, true);
  v.float_bound = float_bound;
  v.correction = v.verified() ? float_bound - v.bound : kInf;
  if (v.verified())
    v.message = fmt::format("verified: bound {:.10g} = float {:.10g} - {:.3g} (residuals {:.3g}, eigenvalues {:.3g})",
                            v.bound, float_bound, v.correction, v.residual_term, v.eigenvalue_term);
  else
    v.message = "unverified: " + v.message;
  return v;
}

VerifiedBound VerifyInfeasibility(const LmiProblem& problem, const std::vector<Eigen::MatrixXd>& X,
                                  const VariableBounds& bounds) {
  VerifiedBound v = Verify(problem, X, bounds, false);
  if (v.verified() && !(v.bound > 0.0)) {
    v.status = VerifyStatus::kUnverified;
    v.message = fmt::format("infeasibility certificate does not verify: rigorous margin {:.3g} <= 0 "
                            "(residuals {:.3g}, eigenvalues {:.3g})",
                            v.bound, v.residual_term, v.eigenvalue_term);
  } else if (v.verified()) {
    v.message = fmt::format("infeasibility verified: rigorous margin {:.3g} > 0", v.bound);
  } else {
    v.message = "infeasibility certificate unverified: " + v.message;
  }
  return v;
}

VerifiedBound VerifyMultiplier(const LmiProblem& problem, const std::vector<Eigen::MatrixXd>& X,
                               const VariableBounds& bounds, double float_bound, double acceptable_correction) {
  VerifiedBound best = VerifyLowerBound(problem, X, bounds, float_bound);
  const bool acceptable =
      best.verified() && best.correction <= acceptable_correction * std::max(1.0, std::abs(float_bound));
  // Cheap remedy for residual-dominated corrections: project X onto the equalities (no re-solve).
  if (!acceptable && X.size() == problem.blocks.size()) {
    const auto P = ProjectOntoEqualities(problem, X);
    if (!P.empty()) {
      VerifiedBound v = VerifyLowerBound(problem, P, bounds, float_bound);
      if (v.verified() && (!best.verified() || v.bound > best.bound)) {
        v.message += " [multiplier projected onto the equalities]";
        best = v;
      }
    }
  }
  return best;
}

VerifiedBound VerifyOptimalSolve(const VerifyOptions& options, const SdpOptions& sdp_options, const LmiProblem& problem,
                                 const VariableBounds& bounds, const SdpSummary& summary, SdpSolver& solver) {
  const auto t0 = Clock::now();
  const double fb = summary.lower_bound;
  auto acceptable = [&](const VerifiedBound& v) {
    return v.verified() && v.correction <= options.acceptable_correction * std::max(1.0, std::abs(fb));
  };
  VerifiedBound best = VerifyMultiplier(problem, summary.X, bounds, fb, options.acceptable_correction);
  // Re-solves only help when the multiplier is not safely PSD: unverified, or the eigenvalue term dominates.
  auto resolve_helps = [&](const VerifiedBound& v) {
    return !v.verified() || (!acceptable(v) && -v.eigenvalue_term > 0.5 * v.correction);
  };
  const double xscale = std::max(1.0, max_abs(summary.X));
  for (int k = 0; k < options.max_resolves && resolve_helps(best) && !summary.X.empty(); ++k) {
    const double eps = options.perturbation * std::pow(10.0, k) * xscale;
    LmiProblem perturbed = problem;
    for (int i = 1; i <= problem.num_vars(); ++i)
      for (const auto& e : problem.F[i])
        if (e.row == e.col) perturbed.c[i - 1] -= eps * e.value;
    SdpOptions so = sdp_options;
    so.keep_dual_matrix = true;
    const auto tr = Clock::now();
    const SdpSummary s = solver.Solve(so, perturbed);
    best.resolve_seconds += std::chrono::duration<double>(Clock::now() - tr).count();
    ++best.resolves;
    if (s.status != SdpStatus::kOptimal || s.X.size() != problem.blocks.size()) continue;
    std::vector<Eigen::MatrixXd> X = s.X;
    for (auto& B : X) B.diagonal().array() += eps;
    VerifiedBound v = VerifyLowerBound(problem, X, bounds, fb);
    if (const auto P = ProjectOntoEqualities(problem, X); !P.empty()) {
      const VerifiedBound vp = VerifyLowerBound(problem, P, bounds, fb);
      if (vp.verified() && (!v.verified() || vp.bound > v.bound)) v = vp;
    }
    if (v.verified() && (!best.verified() || v.bound > best.bound)) {
      v.resolves = best.resolves;
      v.resolve_seconds = best.resolve_seconds;
      v.message += fmt::format(" [after {} perturbed re-solve(s), eps {:.1e}]", v.resolves, eps);
      best = v;
    }
  }
  best.seconds = std::chrono::duration<double>(Clock::now() - t0).count();
  return best;
}

}  // namespace hw::sdp
