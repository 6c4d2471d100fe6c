#include "exact/ipm_solver.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>
#include <fmt/format.h>

#include "exact/gmres.hpp"

namespace hw::exact {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr int kMaxIterations = 60;
constexpr int kStallIterations = 10;
constexpr int kCentralityCorrectors = 2;  // Gondzio's, each one more solve with the same factor
constexpr double kStepFraction = 0.995;  // of the way to the boundary
// Regularisation of the normal equations (NormalEquations::Factorize): the factor only preconditions GMRES, so it
// may be tiny on the columns. On 29 lifted LPs of seed 2 at 31 dB that a stationary refinement left unsolved or
// called infeasible wrongly (docs/exact_set.md), 29 solve with these, 28 with 1e-10 on the columns.
constexpr double kColumnRegularisation = 1e-16;
constexpr double kEqualityRegularisation = 1e-10;

using SparseMatrix = Eigen::SparseMatrix<double, Eigen::ColMajor, int>;
using Vector = Eigen::VectorXd;

// The LP in the solver's form: free columns only (fixed ones moved into the row bounds), rows with at least one
// finite bound. Row i: lo_i <= a_i' x <= hi_i; an equality row has lo_i == hi_i.
struct InteriorForm {
  int n = 0, m = 0;
  SparseMatrix A;                 // m x n
  Vector c, col_lo, col_hi, row_lo, row_hi;
  std::vector<int> column_of;     // free column -> problem column
  std::vector<int> row_of;        // solver row -> problem row
  std::vector<bool> equality;
  double fixed_objective = 0.0;
  std::vector<double> fixed_value;  // problem column -> value if fixed, NaN otherwise
  Vector row_scale, col_scale;      // the scaled problem's x_s = x / col_scale, y_s = y / row_scale
};

// Ruiz equilibration: rows and columns scaled by powers of two (exact in floating point) until every row and
// column of A has its largest entry near 1. The interior-point iterates are far better conditioned; x and y are
// mapped back before anything leaves the solver (x = C x_s, y = R y_s).
void Equilibrate(InteriorForm* f) {
  f->row_scale = Vector::Ones(f->m);
  f->col_scale = Vector::Ones(f->n);
  for (int pass = 0; pass < 8; ++pass) {
    Vector row_max = Vector::Zero(f->m), col_max = Vector::Zero(f->n);
    for (int j = 0; j < f->A.outerSize(); ++j)
      for (SparseMatrix::InnerIterator it(f->A, j); it; ++it) {
        const double a = std::abs(it.value());
        row_max[it.row()] = std::max(row_max[it.row()], a);
        col_max[j] = std::max(col_max[j], a);
      }
    auto power_of_two = [](double norm) { return norm > 0 ? std::exp2(-std::round(std::log2(std::sqrt(norm)))) : 1.0; };
    Vector r(f->m), c(f->n);
    for (int i = 0; i < f->m; ++i) r[i] = power_of_two(row_max[i]);
    for (int j = 0; j < f->n; ++j) c[j] = power_of_two(col_max[j]);
    if ((r.array() == 1.0).all() && (c.array() == 1.0).all()) break;
    f->A = r.asDiagonal() * f->A * c.asDiagonal();
    f->row_scale = f->row_scale.cwiseProduct(r);
    f->col_scale = f->col_scale.cwiseProduct(c);
  }
  // x = C x_s: bounds and costs of x_s; rows scaled by R.
  f->col_lo = f->col_lo.cwiseQuotient(f->col_scale);
  f->col_hi = f->col_hi.cwiseQuotient(f->col_scale);
  f->c = f->c.cwiseProduct(f->col_scale);
  f->row_lo = f->row_lo.cwiseProduct(f->row_scale);
  f->row_hi = f->row_hi.cwiseProduct(f->row_scale);
}

InteriorForm MakeInteriorForm(const LpProblem& p) {
  InteriorForm f;
  const int n0 = p.num_cols(), m0 = p.num_rows();
  std::vector<int> free_index(n0, -1);
  // (Filled below; the scaling comes last.)
  f.fixed_value.assign(n0, std::numeric_limits<double>::quiet_NaN());
  for (int j = 0; j < n0; ++j) {
    if (p.col_hi[j] > p.col_lo[j]) {
      free_index[j] = f.n++;
      f.column_of.push_back(j);
    } else {
      f.fixed_value[j] = p.col_lo[j];
      f.fixed_objective += p.obj[j] * p.col_lo[j];
    }
  }
  std::vector<double> offset(m0, 0.0);
  for (const auto& e : p.entries)
    if (free_index[e.col] < 0) offset[e.row] += e.value * p.col_lo[e.col];
  std::vector<int> solver_row(m0, -1);
  for (int i = 0; i < m0; ++i) {
    if (!std::isfinite(p.row_lo[i]) && !std::isfinite(p.row_hi[i])) continue;
    solver_row[i] = f.m++;
    f.row_of.push_back(i);
  }
  f.c.resize(f.n);
  f.col_lo.resize(f.n);
  f.col_hi.resize(f.n);
  for (int k = 0; k < f.n; ++k) {
    const int j = f.column_of[k];
    f.c[k] = p.obj[j];
    f.col_lo[k] = p.col_lo[j];
    f.col_hi[k] = p.col_hi[j];
  }
  f.row_lo.resize(f.m);
  f.row_hi.resize(f.m);
  f.equality.assign(f.m, false);
  for (int r = 0; r < f.m; ++r) {
    const int i = f.row_of[r];
    f.row_lo[r] = p.row_lo[i] - offset[i];
    f.row_hi[r] = p.row_hi[i] - offset[i];
    if (f.row_lo[r] >= f.row_hi[r]) {  // an equality (or a crossed row made one by the fixed columns)
      f.row_hi[r] = f.row_lo[r];
      f.equality[r] = true;
    }
  }
  std::vector<Eigen::Triplet<double>> triplets;
  triplets.reserve(p.entries.size());
  for (const auto& e : p.entries)
    if (free_index[e.col] >= 0 && solver_row[e.row] >= 0)
      triplets.emplace_back(solver_row[e.row], free_index[e.col], e.value);  // duplicates summed
  f.A.resize(f.m, f.n);
  f.A.setFromTriplets(triplets.begin(), triplets.end());
  Equilibrate(&f);
  return f;
}

// The Newton system reduced to the columns: M dx = fx - A' W g with M = H_x + A' W A, W = 1/(D_r + reg) per row
// (equality rows have D_r = 0: a proximal penalty 1/reg), then dy = -W (A dx + g). M is symmetric positive
// definite, so its Cholesky factor is stable in any order; AMD puts the few dense parameter columns last and the
// banded rest costs time linear in N. The pattern of A'A is analysed once; every iteration only refills values.
class NormalEquations {
 public:
  explicit NormalEquations(const InteriorForm& f) : f_(f) {
    const int n = f.n;
    // Entries of each row (col, value), from the column-major A.
    std::vector<std::vector<std::pair<int, double>>> rows(f.m);
    for (int j = 0; j < f.A.outerSize(); ++j)
      for (SparseMatrix::InnerIterator it(f.A, j); it; ++it) rows[it.row()].emplace_back(j, it.value());
    std::vector<Eigen::Triplet<double>> t;
    for (int j = 0; j < n; ++j) t.emplace_back(j, j, 1.0);
    for (const auto& row : rows)
      for (std::size_t a = 0; a < row.size(); ++a)
        for (std::size_t b = 0; b <= a; ++b) {
          const int hi = std::max(row[a].first, row[b].first), lo = std::min(row[a].first, row[b].first);
          t.emplace_back(hi, lo, 1.0);
        }
    M_.resize(n, n);
    M_.setFromTriplets(t.begin(), t.end());
    M_.makeCompressed();
    // Where each pair's product lands in M's value array.
    auto position = [&](int r, int c) {
      const int* begin = M_.innerIndexPtr() + M_.outerIndexPtr()[c];
      const int* end = M_.innerIndexPtr() + M_.outerIndexPtr()[c + 1];
      return static_cast<int>(std::lower_bound(begin, end, r) - M_.innerIndexPtr());
    };
    diagonal_.resize(n);
    for (int j = 0; j < n; ++j) diagonal_[j] = position(j, j);
    row_begin_.push_back(0);
    for (const auto& row : rows) {
      for (std::size_t a = 0; a < row.size(); ++a)
        for (std::size_t b = 0; b <= a; ++b) {
          const int hi = std::max(row[a].first, row[b].first), lo = std::min(row[a].first, row[b].first);
          pair_position_.push_back(position(hi, lo));
          pair_product_.push_back(row[a].second * row[b].second * (a == b ? 1.0 : (row[a].first == row[b].first ? 2.0 : 1.0)));
        }
      row_begin_.push_back(static_cast<int>(pair_position_.size()));
    }
    llt_.analyzePattern(M_);
  }

  // `column_regularisation` is added to H_x, `row_regularisation` to D_r (the only term of an equality row).
  bool Factorize(const Vector& h_x, const Vector& d_r, double column_regularisation, double row_regularisation) {
    h_x_ = h_x;
    d_r_ = d_r;
    w_ = (d_r.array() + row_regularisation).inverse().matrix();
    double* v = M_.valuePtr();
    std::fill(v, v + M_.nonZeros(), 0.0);
    for (int j = 0; j < f_.n; ++j) v[diagonal_[j]] = h_x[j] + column_regularisation;
    for (int i = 0; i < f_.m; ++i)
      for (int k = row_begin_[i]; k < row_begin_[i + 1]; ++k) v[pair_position_[k]] += w_[i] * pair_product_[k];
    llt_.factorize(M_);
    return llt_.info() == Eigen::Success;
  }

  // Solves H_x dx - A' dy = fx, -A dx - D_r dy = g (unregularised): the regularised solve, then GMRES on these
  // equations preconditioned by it (exact/gmres.hpp), to kSolveTolerance of the right-hand side. Whatever
  // residual is left becomes dual infeasibility of the next iterate, and the dual bound pays it times the
  // columns' ranges; a stationary refinement diverged near the optimum of the lifted LPs.
  void Solve(const Vector& fx, const Vector& g, Vector* dx, Vector* dy) const {
    const int n = f_.n, m = f_.m;
    auto apply = [&](const Vector& u) {
      Vector out(n + m);
      out.head(n) = h_x_.cwiseProduct(u.head(n)) - f_.A.transpose() * u.tail(m);
      out.tail(m) = -(f_.A * u.head(n)) - d_r_.cwiseProduct(u.tail(m));
      return out;
    };
    auto precondition = [&](const Vector& r) {
      Vector cx, cy, out(n + m);
      SolveRegularised(r.head(n), r.tail(m), &cx, &cy);
      out << cx, cy;
      return out;
    };
    Vector b(n + m);
    b << fx, g;
    Vector u = precondition(b);
    GmresOptions options;
    options.tolerance = kSolveTolerance * (1.0 + b.lpNorm<Eigen::Infinity>());
    SolveGmres(apply, precondition, b, options, &u);
    *dx = u.head(n);
    *dy = u.tail(m);
  }

 private:
  static constexpr double kSolveTolerance = 1e-12;

  void SolveRegularised(const Vector& fx, const Vector& g, Vector* dx, Vector* dy) const {
    *dx = llt_.solve(fx - f_.A.transpose() * w_.cwiseProduct(g));
    *dy = -w_.cwiseProduct(f_.A * *dx + g);
  }

  const InteriorForm& f_;
  Vector h_x_, d_r_;
  SparseMatrix M_;
  std::vector<int> diagonal_, row_begin_, pair_position_;
  std::vector<double> pair_product_;
  Vector w_;
  Eigen::SimplicialLLT<SparseMatrix, Eigen::Lower, Eigen::AMDOrdering<int>> llt_;
};

// Primal-dual iterate. Columns keep l < x < u; inequality rows keep their activity r strictly inside its finite
// bounds; z_* are the multipliers of the bounds (zero where the bound is infinite).
struct Iterate {
  Vector x, r, y, zl, zu, zrl, zru;
};

struct Direction {
  Vector dx, dr, dy, dzl, dzu, dzrl, dzru;
};

bool Finite(double v) { return std::isfinite(v); }

// Mehrotra's method on the interior form. Keeps the data read-only; owns the iterate.
class InteriorPoint {
 public:
  InteriorPoint(const InteriorForm& f, const LpSolveOptions& options)
      : f_(f), options_(options), system_(f), At_(f.A.transpose()) {}

  // Iterates until optimal, past the cutoff, stalled (no progress for kStallIterations)
  // or out of iterations. The dual vector returned is the best one seen, not the last.
  LpStatus Run(int* iterations) {
    Start();
    best_y_ = it_.y;
    int since_progress = 0;
    double lowest[3] = {kInf, kInf, kInf};
    for (int k = 0; k < kMaxIterations; ++k) {
      *iterations = k;
      Residuals();
      const double pobj = PrimalObjective(), dobj = DualObjective();
      const double scale = 1.0 + std::abs(pobj);
      if (dobj > best_dual_) best_dual_ = dobj, best_y_ = it_.y;
      // Progress: the complementarity, the primal infeasibility or the gap to the best dual bound reaches a new
      // low (by 1 % or more).
      const double measures[3] = {Mu(), primal_infeasibility_, std::max(0.0, pobj - best_dual_)};
      ++since_progress;
      for (int q = 0; q < 3; ++q)
        if (measures[q] < 0.99 * lowest[q]) lowest[q] = measures[q], since_progress = 0;
      if (best_dual_ > options_.objective_cutoff + 1e-7 * scale) return LpStatus::kCutoff;
      if (primal_infeasibility_ <= options_.primal_tolerance && pobj - best_dual_ <= kGapTolerance * scale)
        return LpStatus::kOptimal;
      if (since_progress >= kStallIterations) return Stopped(LpStatus::kIterationLimit, pobj);
      if (!Step()) return Stopped(LpStatus::kFailed, pobj);
    }
    *iterations = kMaxIterations;
    return Stopped(LpStatus::kIterationLimit, PrimalObjective());
  }

  // The status of a solve that stops short. Its dual bound far above the objective of an infeasible iterate:
  // the dual was diverging, the sign of an infeasible LP (the caller proves emptiness on its own). Feasible and
  // within kStalledGapTolerance (or the caller's acceptable gap) of its dual bound: optimal to that tolerance.
  LpStatus Stopped(LpStatus status, double pobj) const {
    const double scale = 1.0 + std::abs(pobj);
    const bool feasible = primal_infeasibility_ <= options_.primal_tolerance;
    if (!feasible && best_dual_ > pobj + 1e-3 * scale && ProvesInfeasible(best_y_)) return LpStatus::kInfeasible;
    if (feasible && pobj - best_dual_ <= std::max(kStalledGapTolerance * scale, options_.acceptable_gap))
      return LpStatus::kOptimal;
    return status;
  }

  const Vector& best_duals() const { return best_y_; }
  double best_dual_bound() const { return best_dual_; }
  double primal_infeasibility() const { return primal_infeasibility_; }

  const Iterate& iterate() const { return it_; }

  // The Lagrangian dual bound min over the column box and the row bounds of c'x - y'(Ax - r), with y clamped to
  // the sign its row's finite bound allows (the same clamp as the certificate), in floating point.
  double DualObjective() const { return LagrangianBound(it_.y, f_.c, nullptr) + f_.fixed_objective; }
  double PrimalObjective() const { return f_.c.dot(it_.x) + f_.fixed_objective; }

  // Whether y, as a Farkas vector, shows in floating point that no x in the column box meets the rows: the
  // Lagrangian bound of the zero objective, sum_i y_i (row bound) + sum_j min over [lo, hi] of (-A'y)_j x_j, is
  // positive by more than the rounding of its terms. A diverging iterate also drives the dual bound of the true
  // objective up through cancellation; without this check such a solve was called infeasible on an LP whose
  // other objectives had just been solved (the same rows), and the caller lost that step.
  bool ProvesInfeasible(const Vector& y_in) const {
    const double norm = y_in.lpNorm<Eigen::Infinity>();
    if (!(norm > 0) || !std::isfinite(norm)) return false;
    double magnitude = 0.0;
    const double total = LagrangianBound(y_in / norm, Vector::Zero(f_.n), &magnitude);
    return total > kFarkasMargin * magnitude;
  }

  // min over the column box and the row bounds of c'x - y'(Ax - r) (without the fixed columns' constant), with
  // y clamped to the sign its row's finite bound allows (the same clamp as the certificate), in floating point.
  // `magnitude`, when given, receives the sum of the terms' absolute values.
  double LagrangianBound(Vector y, const Vector& c, double* magnitude) const {
    double total = 0.0, size = 0.0;
    auto add = [&](double term) { total += term, size += std::abs(term); };
    for (int i = 0; i < f_.m; ++i) {
      if (y[i] > 0 && Finite(f_.row_lo[i])) add(y[i] * f_.row_lo[i]);
      else if (y[i] < 0 && Finite(f_.row_hi[i])) add(y[i] * f_.row_hi[i]);
      else y[i] = 0.0;
    }
    const Vector reduced = c - At_ * y;
    for (int j = 0; j < f_.n; ++j) add(reduced[j] * (reduced[j] > 0 ? f_.col_lo[j] : f_.col_hi[j]));
    if (magnitude) *magnitude = size;
    return total;
  }

 private:
  static constexpr double kGapTolerance = 1e-9;
  static constexpr double kStalledGapTolerance = 1e-7;
  static constexpr double kFarkasMargin = 1e-9;  // of the sum of |terms|: above the rounding of the sum

  void Start() {
    const int m = f_.m;
    it_.x = 0.5 * (f_.col_lo + f_.col_hi);
    const Vector ax = f_.A * it_.x;
    it_.r = ax;
    for (int i = 0; i < m; ++i) {
      if (f_.equality[i]) {
        it_.r[i] = f_.row_lo[i];
        continue;
      }
      const double lo = f_.row_lo[i], hi = f_.row_hi[i];
      if (Finite(lo) && Finite(hi)) it_.r[i] = std::clamp(ax[i], lo + 0.25 * (hi - lo), hi - 0.25 * (hi - lo));
      else if (Finite(lo)) it_.r[i] = std::max(ax[i], lo + 1.0);
      else it_.r[i] = std::min(ax[i], hi - 1.0);
    }
    it_.y = Vector::Zero(m);
    it_.zl = (it_.x - f_.col_lo).cwiseInverse();
    it_.zu = (f_.col_hi - it_.x).cwiseInverse();
    it_.zrl = Vector::Zero(m);
    it_.zru = Vector::Zero(m);
    for (int i = 0; i < m; ++i) {
      if (f_.equality[i]) continue;
      if (Finite(f_.row_lo[i])) it_.zrl[i] = 1.0 / (it_.r[i] - f_.row_lo[i]);
      if (Finite(f_.row_hi[i])) it_.zru[i] = 1.0 / (f_.row_hi[i] - it_.r[i]);
    }
  }

  // Residuals of the current iterate: rp = Ax - r, rd_x = c - A'y - zl + zu, rd_r = y - zrl + zru.
  void Residuals() {
    const Vector ax = f_.A * it_.x;
    rp_ = ax - it_.r;
    rd_x_ = f_.c - At_ * it_.y - it_.zl + it_.zu;
    rd_r_ = it_.y - it_.zrl + it_.zru;
    for (int i = 0; i < f_.m; ++i)
      if (f_.equality[i]) rd_r_[i] = 0.0;
    const double size = 1.0 + std::max(ax.lpNorm<Eigen::Infinity>(), it_.r.lpNorm<Eigen::Infinity>());
    primal_infeasibility_ = (f_.m ? rp_.lpNorm<Eigen::Infinity>() : 0.0) / size;
  }

  double Mu() const {
    double sum = 0.0;
    int count = 0;
    for (int j = 0; j < f_.n; ++j) {
      sum += (it_.x[j] - f_.col_lo[j]) * it_.zl[j] + (f_.col_hi[j] - it_.x[j]) * it_.zu[j];
      count += 2;
    }
    for (int i = 0; i < f_.m; ++i) {
      if (f_.equality[i]) continue;
      if (Finite(f_.row_lo[i])) sum += (it_.r[i] - f_.row_lo[i]) * it_.zrl[i], ++count;
      if (Finite(f_.row_hi[i])) sum += (f_.row_hi[i] - it_.r[i]) * it_.zru[i], ++count;
    }
    return count ? sum / count : 0.0;
  }

  // The wanted change of every product s * z of a bound pair (columns' lower and upper, rows' lower and upper).
  struct Complementarity {
    Vector l, u, rl, ru;
  };

  // Mehrotra's right-hand side: towards `target`, less the predictor's second-order term when given.
  Complementarity MehrotraRhs(double target, const Direction* affine) const {
    const int n = f_.n, m = f_.m;
    Complementarity rc{Vector(n), Vector(n), Vector::Zero(m), Vector::Zero(m)};
    for (int j = 0; j < n; ++j) {
      rc.l[j] = target - (it_.x[j] - f_.col_lo[j]) * it_.zl[j] - (affine ? affine->dx[j] * affine->dzl[j] : 0.0);
      rc.u[j] = target - (f_.col_hi[j] - it_.x[j]) * it_.zu[j] + (affine ? affine->dx[j] * affine->dzu[j] : 0.0);
    }
    for (int i = 0; i < m; ++i) {
      if (f_.equality[i]) continue;
      if (Finite(f_.row_lo[i]))
        rc.rl[i] = target - (it_.r[i] - f_.row_lo[i]) * it_.zrl[i] - (affine ? affine->dr[i] * affine->dzrl[i] : 0.0);
      if (Finite(f_.row_hi[i]))
        rc.ru[i] = target - (f_.row_hi[i] - it_.r[i]) * it_.zru[i] + (affine ? affine->dr[i] * affine->dzru[i] : 0.0);
    }
    return rc;
  }

  // Gondzio's centrality corrector: the products a longer step along `d` would reach, pulled back into
  // [0.1, 10] x target, added to `base`. Stalls come from a few products far below the others.
  Complementarity GondzioRhs(const Complementarity& base, const Direction& d, double ap, double ad, double target) const {
    const double ap_t = std::min(1.0, 1.5 * ap + 0.1), ad_t = std::min(1.0, 1.5 * ad + 0.1);
    const double lo = 0.1 * target, hi = 10.0 * target;
    auto correction = [&](double s, double ds, double z, double dz) {
      const double v = (s + ap_t * ds) * (z + ad_t * dz);
      return std::max(std::clamp(v, lo, hi) - v, -hi);
    };
    Complementarity rc = base;
    for (int j = 0; j < f_.n; ++j) {
      rc.l[j] += correction(it_.x[j] - f_.col_lo[j], d.dx[j], it_.zl[j], d.dzl[j]);
      rc.u[j] += correction(f_.col_hi[j] - it_.x[j], -d.dx[j], it_.zu[j], d.dzu[j]);
    }
    for (int i = 0; i < f_.m; ++i) {
      if (f_.equality[i]) continue;
      if (Finite(f_.row_lo[i])) rc.rl[i] += correction(it_.r[i] - f_.row_lo[i], d.dr[i], it_.zrl[i], d.dzrl[i]);
      if (Finite(f_.row_hi[i])) rc.ru[i] += correction(f_.row_hi[i] - it_.r[i], -d.dr[i], it_.zru[i], d.dzru[i]);
    }
    return rc;
  }

  // Solves the Newton system for the wanted complementarity changes `rc`.
  Direction Solve(const Complementarity& rc) {
    const int n = f_.n, m = f_.m;
    const Vector sl = it_.x - f_.col_lo, su = f_.col_hi - it_.x;
    Vector fx(n);
    for (int j = 0; j < n; ++j) fx[j] = -rd_x_[j] + rc.l[j] / sl[j] - rc.u[j] / su[j];
    Vector rhs_r(m);
    for (int i = 0; i < m; ++i) {
      if (f_.equality[i]) {
        rhs_r[i] = rp_[i];
        continue;
      }
      double fr = -rd_r_[i];
      if (Finite(f_.row_lo[i])) fr += rc.rl[i] / (it_.r[i] - f_.row_lo[i]);
      if (Finite(f_.row_hi[i])) fr -= rc.ru[i] / (f_.row_hi[i] - it_.r[i]);
      rhs_r[i] = rp_[i] - d_r_[i] * fr;
    }
    Direction d;
    system_.Solve(fx, rhs_r, &d.dx, &d.dy);
    d.dr = f_.A * d.dx + rp_;
    for (int i = 0; i < m; ++i)
      if (f_.equality[i]) d.dr[i] = 0.0;
    d.dzl = (rc.l - it_.zl.cwiseProduct(d.dx)).cwiseQuotient(sl);
    d.dzu = (rc.u + it_.zu.cwiseProduct(d.dx)).cwiseQuotient(su);
    d.dzrl = Vector::Zero(m);
    d.dzru = Vector::Zero(m);
    for (int i = 0; i < m; ++i) {
      if (f_.equality[i]) continue;
      if (Finite(f_.row_lo[i])) d.dzrl[i] = (rc.rl[i] - it_.zrl[i] * d.dr[i]) / (it_.r[i] - f_.row_lo[i]);
      if (Finite(f_.row_hi[i])) d.dzru[i] = (rc.ru[i] + it_.zru[i] * d.dr[i]) / (f_.row_hi[i] - it_.r[i]);
    }
    return d;
  }

  // Largest steps in (0, 1] that keep the slacks and the multipliers positive.
  std::pair<double, double> StepLengths(const Direction& d) const {
    double ap = 1.0, ad = 1.0;
    auto limit = [](double value, double change, double& alpha) {
      if (change < 0) alpha = std::min(alpha, -value / change);
    };
    for (int j = 0; j < f_.n; ++j) {
      limit(it_.x[j] - f_.col_lo[j], d.dx[j], ap);
      limit(f_.col_hi[j] - it_.x[j], -d.dx[j], ap);
      limit(it_.zl[j], d.dzl[j], ad);
      limit(it_.zu[j], d.dzu[j], ad);
    }
    for (int i = 0; i < f_.m; ++i) {
      if (f_.equality[i]) continue;
      if (Finite(f_.row_lo[i])) limit(it_.r[i] - f_.row_lo[i], d.dr[i], ap), limit(it_.zrl[i], d.dzrl[i], ad);
      if (Finite(f_.row_hi[i])) limit(f_.row_hi[i] - it_.r[i], -d.dr[i], ap), limit(it_.zru[i], d.dzru[i], ad);
    }
    return {ap, ad};
  }

  double MuAfter(const Direction& d, double ap, double ad) const {
    double sum = 0.0;
    int count = 0;
    for (int j = 0; j < f_.n; ++j) {
      sum += (it_.x[j] + ap * d.dx[j] - f_.col_lo[j]) * (it_.zl[j] + ad * d.dzl[j]);
      sum += (f_.col_hi[j] - it_.x[j] - ap * d.dx[j]) * (it_.zu[j] + ad * d.dzu[j]);
      count += 2;
    }
    for (int i = 0; i < f_.m; ++i) {
      if (f_.equality[i]) continue;
      const double r = it_.r[i] + ap * d.dr[i];
      if (Finite(f_.row_lo[i])) sum += (r - f_.row_lo[i]) * (it_.zrl[i] + ad * d.dzrl[i]), ++count;
      if (Finite(f_.row_hi[i])) sum += (f_.row_hi[i] - r) * (it_.zru[i] + ad * d.dzru[i]), ++count;
    }
    return count ? sum / count : 0.0;
  }

  bool Step() {
    const int n = f_.n, m = f_.m;
    Vector h_x(n);
    for (int j = 0; j < n; ++j)
      h_x[j] = it_.zl[j] / (it_.x[j] - f_.col_lo[j]) + it_.zu[j] / (f_.col_hi[j] - it_.x[j]);
    d_r_ = Vector::Zero(m);
    for (int i = 0; i < m; ++i) {
      if (f_.equality[i]) continue;
      double h = 0.0;
      if (Finite(f_.row_lo[i])) h += it_.zrl[i] / (it_.r[i] - f_.row_lo[i]);
      if (Finite(f_.row_hi[i])) h += it_.zru[i] / (f_.row_hi[i] - it_.r[i]);
      d_r_[i] = 1.0 / h;
    }
    // Regularisation keeps the factorisation possible: tiny on the columns (an interior column's H_x falls to
    // 1e-12 near the optimum; GMRES undoes the shift). Both are raised together until the factorisation succeeds.
    bool factored = false;
    for (double raise = 1.0; raise <= 1e6 && !factored; raise *= 100)
      factored = system_.Factorize(h_x, d_r_, kColumnRegularisation * raise, kEqualityRegularisation * raise);
    if (!factored) return false;
    const double mu = Mu();
    const Direction affine = Solve(MehrotraRhs(0.0, nullptr));
    const auto [ap_aff, ad_aff] = StepLengths(affine);
    const double mu_aff = MuAfter(affine, ap_aff, ad_aff);
    const double sigma = std::pow(std::clamp(mu_aff / mu, 0.0, 1.0), 3);
    Complementarity rc = MehrotraRhs(sigma * mu, &affine);
    Direction d = Solve(rc);
    auto [ap, ad] = StepLengths(d);
    for (int k = 0; k < kCentralityCorrectors; ++k) {
      const Complementarity rc_k = GondzioRhs(rc, d, ap, ad, sigma * mu);
      Direction d_k = Solve(rc_k);
      const auto [ap_k, ad_k] = StepLengths(d_k);
      if (std::min(ap_k, ad_k) < 1.01 * std::min(ap, ad)) break;  // no longer steps: keep the last direction
      rc = rc_k, d = std::move(d_k), ap = ap_k, ad = ad_k;
    }
    ap = std::min(1.0, kStepFraction * ap);
    ad = std::min(1.0, kStepFraction * ad);
    if (!(ap > 0) || !(ad > 0) || !d.dx.allFinite() || !d.dy.allFinite()) return false;
    it_.x += ap * d.dx;
    it_.r += ap * d.dr;
    it_.y += ad * d.dy;
    it_.zl += ad * d.dzl;
    it_.zu += ad * d.dzu;
    it_.zrl += ad * d.dzrl;
    it_.zru += ad * d.dzru;
    return true;
  }

  const InteriorForm& f_;
  const LpSolveOptions& options_;
  NormalEquations system_;
  SparseMatrix At_;
  Iterate it_;
  Vector rp_, rd_x_, rd_r_, d_r_;
  Vector best_y_;
  double best_dual_ = -kInf;
  double primal_infeasibility_ = kInf;
};

}  // namespace

LpResult IpmSolver::Solve(const LpProblem& problem, const LpBasis& /*warm*/, const LpSolveOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  LpResult result;
  const InteriorForm form = MakeInteriorForm(problem);
  InteriorPoint ipm(form, options);
  result.status = ipm.Run(&result.iterations);
  const Iterate& it = ipm.iterate();
  result.objective = ipm.PrimalObjective();
  // Back to the problem's units: x = C x_s, y = R y_s; fixed columns at their value.
  result.primal.assign(problem.num_cols(), 0.0);
  for (int j = 0; j < problem.num_cols(); ++j)
    if (!std::isnan(form.fixed_value[j])) result.primal[j] = form.fixed_value[j];
  for (int k = 0; k < form.n; ++k) result.primal[form.column_of[k]] = form.col_scale[k] * it.x[k];
  result.duals.assign(problem.num_rows(), 0.0);
  for (int r = 0; r < form.m; ++r) result.duals[form.row_of[r]] = form.row_scale[r] * ipm.best_duals()[r];
  if (result.status != LpStatus::kOptimal && result.status != LpStatus::kCutoff)
    result.message = fmt::format("interior point: {} after {} iterations (primal infeasibility {:.3g}, objective {:.10g}, "
                                 "best dual bound {:.10g})", ToString(result.status), result.iterations,
                                 ipm.primal_infeasibility(), result.objective, ipm.best_dual_bound());
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace hw::exact
