#include "pop/moment_relaxation.hpp"

#include "pop/constraint_generation.hpp"
#include "sdp/verified_bound.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <random>
#include <tuple>

#include <fmt/format.h>

namespace hw::pop {
namespace {

constexpr int kBitsPerExponent = 6;  // exponents up to 63; 10 variables fit in 60 bits

int ceil_half(int d) { return (d + 1) / 2; }

// Sorts entries of every matrix and merges duplicates; drops exact zeros.
void canonicalize(sdp::LmiProblem& lmi) {
  for (auto& mat : lmi.F) {
    std::sort(mat.begin(), mat.end(), [](const sdp::Entry& a, const sdp::Entry& b) {
      return std::tie(a.block, a.row, a.col) < std::tie(b.block, b.row, b.col);
    });
    std::vector<sdp::Entry> merged;
    for (const auto& e : mat) {
      if (!merged.empty() && merged.back().block == e.block && merged.back().row == e.row && merged.back().col == e.col)
        merged.back().value += e.value;
      else
        merged.push_back(e);
    }
    merged.erase(std::remove_if(merged.begin(), merged.end(), [](const sdp::Entry& e) { return e.value == 0.0; }),
                 merged.end());
    mat = std::move(merged);
  }
}

}  // namespace

bool PolyProblem::IsValid(std::string* error) const {
  auto fail = [&](std::string m) {
    if (error) *error = std::move(m);
    return false;
  };
  if (num_vars <= 0) return fail("the problem needs at least one variable");
  if (!names.empty() && static_cast<int>(names.size()) != num_vars) return fail("names must list every variable");
  auto check = [&](const Polynomial& p, const std::string& what) {
    if (p.num_vars() != num_vars) return fail(fmt::format("{} has {} variables, expected {}", what, p.num_vars(), num_vars));
    for (const auto& [e, c] : p.terms())
      if (!std::isfinite(c)) return fail(fmt::format("{} has a non-finite coefficient", what));
    return true;
  };
  if (!check(objective, "the objective")) return false;
  for (std::size_t i = 0; i < inequalities.size(); ++i)
    if (!check(inequalities[i], fmt::format("inequality {}", i + 1))) return false;
  for (std::size_t i = 0; i < equalities.size(); ++i)
    if (!check(equalities[i], fmt::format("equality {}", i + 1))) return false;
  if (!box.empty()) {
    if (static_cast<int>(box.size()) != num_vars) return fail("box must give [lo, hi] for every variable");
    for (const auto& [lo, hi] : box)
      if (!(lo < hi) || !std::isfinite(lo) || !std::isfinite(hi)) return fail("box bounds must be finite with lo < hi");
  }
  return true;
}

int PolyProblem::max_degree() const {
  int d = std::max(1, objective.degree());
  for (const auto& g : inequalities) d = std::max(d, g.degree());
  for (const auto& h : equalities) d = std::max(d, h.degree());
  if (!box.empty()) d = std::max(d, 2);
  return d;
}

int PolyProblem::minimal_order() const { return ceil_half(max_degree()); }

bool RelaxationOptions::IsValid(std::string* error) const {
  if (order < 0) {
    if (error) *error = "order must be >= 0 (0 = minimal)";
    return false;
  }
  if (!(rank_tolerance > 0 && rank_tolerance < 1)) {
    if (error) *error = "rank_tolerance must lie in (0, 1)";
    return false;
  }
  return sdp.IsValid(error);
}

MomentIndex::MomentIndex(int num_vars, int max_degree) : basis_(num_vars, max_degree) {
  packed_ = num_vars * kBitsPerExponent <= 64 && max_degree < (1 << kBitsPerExponent);
  if (!packed_) return;
  keys_.resize(basis_.size());
  for (std::size_t i = 0; i < basis_.size(); ++i) {
    uint64_t k = 0;
    for (int v = 0; v < num_vars; ++v) k |= static_cast<uint64_t>(basis_[i][v]) << (kBitsPerExponent * v);
    keys_[i] = k;
    by_key_.emplace(k, static_cast<long>(i));
  }
}

long MomentIndex::product(long i, long j) const {
  if (packed_) {
    // Adding packed keys adds exponents; no carry since the sum's degree is checked by the lookup
    // (a sum whose exponent overflows a field has degree > max_degree < 64 only if max_degree >= 32).
    if (degree_of(basis_[i]) + degree_of(basis_[j]) > basis_.max_degree()) return -1;
    auto it = by_key_.find(keys_[i] + keys_[j]);
    return it == by_key_.end() ? -1 : it->second;
  }
  return basis_.index_of(add_exponents(basis_[i], basis_[j]));
}

MomentRelaxation::MomentRelaxation(const PolyProblem& problem, int order)
    : MomentRelaxation(problem, order, std::vector<int>(problem.inequalities.size(), -1)) {}

MomentRelaxation::MomentRelaxation(const PolyProblem& problem, int order, const std::vector<int>& localizing_orders)
    : order_(order), sign_(problem.maximize ? -1.0 : 1.0), index_(problem.num_vars, 2 * order) {
  const int n = problem.num_vars;
  const MonomialBasis& full = index_.basis();
  const int m_full = static_cast<int>(full.size()) - 1;  // y_0 is the constant 1

  if (localizing_orders.size() != problem.inequalities.size())
    throw std::invalid_argument("MomentRelaxation: one localizing order per inequality expected");
  std::vector<Polynomial> inequalities = problem.inequalities;
  std::vector<int> cap = localizing_orders;
  cap.resize(inequalities.size() + problem.box.size(), -1);
  for (int i = 0; i < static_cast<int>(problem.box.size()); ++i) {
    const auto [lo, hi] = problem.box[i];
    const auto x = Polynomial::Variable(n, i);
    inequalities.push_back((x - Polynomial::Constant(n, lo)) * (Polynomial::Constant(n, hi) - x));
  }

  sdp::LmiProblem lmi;
  lmi.c.assign(m_full, 0.0);
  lmi.F.assign(m_full + 1, {});
  auto add_moment = [&](long moment, int block, int r, int c, double v) {
    // F(y) = sum y_i F_i - F_0: the constant moment y_0 = 1 contributes -F_0.
    if (moment == 0)
      lmi.F[0].push_back({block, r, c, -v});
    else
      lmi.F[moment].push_back({block, r, c, v});
  };

  // Moment matrix.
  const int s_delta = static_cast<int>(MonomialBasis::count(n, order));
  lmi.blocks.push_back({sdp::BlockSpec::Kind::kPsd, s_delta});
  for (int r = 0; r < s_delta; ++r)
    for (int c = r; c < s_delta; ++c) add_moment(index_.product(r, c), 0, r, c, 1.0);

  // Localizing matrices; order-0 ones go to one diagonal block at the end.
  std::vector<const Polynomial*> scalar;
  for (std::size_t i = 0; i < inequalities.size(); ++i) {
    const Polynomial& g = inequalities[i];
    const int full_k = order - ceil_half(std::max(0, g.degree()));
    if (full_k < 0) throw std::invalid_argument(fmt::format("relaxation order {} is below the minimal order", order));
    const int k = cap[i] < 0 ? full_k : std::min(cap[i], full_k);
    if (k == 0) {
      scalar.push_back(&g);
      block_of_inequality_.push_back(-1);
      continue;
    }
    const int size = static_cast<int>(MonomialBasis::count(n, k));
    const int block = static_cast<int>(lmi.blocks.size());
    block_of_inequality_.push_back(block);
    lmi.blocks.push_back({sdp::BlockSpec::Kind::kPsd, size});
    for (const auto& [e, coef] : g.terms()) {
      const long gi = index_.index_of(e);
      for (int r = 0; r < size; ++r)
        for (int c = r; c < size; ++c) add_moment(index_.product(index_.product(r, c), gi), block, r, c, coef);
    }
  }
  if (!scalar.empty()) {
    const int block = static_cast<int>(lmi.blocks.size());
    lmi.blocks.push_back({sdp::BlockSpec::Kind::kDiagonal, static_cast<int>(scalar.size())});
    for (int r = 0; r < static_cast<int>(scalar.size()); ++r)
      for (const auto& [e, coef] : scalar[r]->terms()) add_moment(index_.index_of(e), block, r, r, coef);
  }

  // Objective (the LMI always minimises sign * f).
  for (const auto& [e, coef] : problem.objective.terms()) {
    const long k = index_.index_of(e);
    if (k == 0)
      lmi.objective_offset += sign_ * coef;
    else
      lmi.c[k - 1] += sign_ * coef;
  }
  canonicalize(lmi);

  // Equalities: rows  sum_gamma h_gamma y_{beta + gamma} = 0, eliminated by reduced row echelon form.
  std::vector<Eigen::VectorXd> rows;
  std::vector<double> rhs;
  for (const auto& h : problem.equalities) {
    const int room = 2 * order - std::max(0, h.degree());
    if (room < 0) throw std::invalid_argument("relaxation order below the equality's degree");
    const long count = static_cast<long>(MonomialBasis::count(n, room));
    for (long b = 0; b < count; ++b) {
      Eigen::VectorXd row = Eigen::VectorXd::Zero(m_full);
      double r0 = 0.0;
      for (const auto& [e, coef] : h.terms()) {
        const long k = index_.product(b, index_.index_of(e));
        if (k == 0)
          r0 -= coef;
        else
          row[k - 1] += coef;
      }
      rows.push_back(std::move(row));
      rhs.push_back(r0);
    }
  }
  base_.assign(m_full, 0.0);
  map_.assign(m_full, {});
  if (rows.empty()) {
    for (int i = 0; i < m_full; ++i) map_[i] = {{i, 1.0}};
    lmi_ = std::move(lmi);
    return;
  }
  Eigen::MatrixXd E(rows.size(), m_full + 1);
  for (std::size_t r = 0; r < rows.size(); ++r) {
    E.row(r).head(m_full) = rows[r].transpose();
    E(r, m_full) = rhs[r];
  }
  const double tol = 1e-10 * std::max(1.0, E.cwiseAbs().maxCoeff());
  std::vector<int> pivot_of_col(m_full, -1);
  int rank = 0;
  for (int col = 0; col < m_full && rank < E.rows(); ++col) {
    Eigen::Index best;
    const double mag = E.col(col).tail(E.rows() - rank).cwiseAbs().maxCoeff(&best);
    if (mag <= tol) continue;
    E.row(rank).swap(E.row(rank + best));
    E.row(rank) /= E(rank, col);
    for (Eigen::Index r = 0; r < E.rows(); ++r)
      if (r != rank && E(r, col) != 0.0) E.row(r) -= E(r, col) * E.row(rank);
    pivot_of_col[col] = rank++;
  }
  for (Eigen::Index r = rank; r < E.rows(); ++r)
    if (std::abs(E(r, m_full)) > 1e-8 * std::max(1.0, E.cwiseAbs().maxCoeff()))
      throw std::domain_error("the equality constraints are inconsistent (no moment vector satisfies them)");
  std::vector<int> free_index(m_full, -1);
  int num_free = 0;
  for (int col = 0; col < m_full; ++col)
    if (pivot_of_col[col] < 0) free_index[col] = num_free++;
  for (int col = 0; col < m_full; ++col) {
    if (pivot_of_col[col] < 0) {
      map_[col] = {{free_index[col], 1.0}};
      continue;
    }
    const int r = pivot_of_col[col];
    base_[col] = E(r, m_full);
    for (int f = 0; f < m_full; ++f)
      if (free_index[f] >= 0 && std::abs(E(r, f)) > tol) map_[col].push_back({free_index[f], -E(r, f)});
  }
  // Substitute y = base + T z into the LMI and the objective.
  sdp::LmiProblem reduced;
  reduced.blocks = lmi.blocks;
  reduced.c.assign(num_free, 0.0);
  reduced.F.assign(num_free + 1, {});
  reduced.F[0] = lmi.F[0];
  reduced.objective_offset = lmi.objective_offset;
  for (int i = 0; i < m_full; ++i) {
    reduced.objective_offset += lmi.c[i] * base_[i];
    for (const auto& [f, t] : map_[i]) reduced.c[f] += lmi.c[i] * t;
    for (const auto& e : lmi.F[i + 1]) {
      if (base_[i] != 0.0) reduced.F[0].push_back({e.block, e.row, e.col, -base_[i] * e.value});
      for (const auto& [f, t] : map_[i]) reduced.F[f + 1].push_back({e.block, e.row, e.col, t * e.value});
    }
  }
  canonicalize(reduced);
  lmi_ = std::move(reduced);
}

std::vector<double> MomentRelaxation::moments(const std::vector<double>& z) const {
  std::vector<double> y(map_.size() + 1);
  y[0] = 1.0;
  for (std::size_t i = 0; i < map_.size(); ++i) {
    double v = base_[i];
    for (const auto& [f, t] : map_[i]) v += t * z[f];
    y[i + 1] = v;
  }
  return y;
}

Eigen::MatrixXd MomentRelaxation::moment_matrix(const std::vector<double>& y, int k) const {
  const int size = static_cast<int>(MonomialBasis::count(index_.basis().num_vars(), k));
  Eigen::MatrixXd M(size, size);
  for (int r = 0; r < size; ++r)
    for (int c = r; c < size; ++c) M(r, c) = M(c, r) = y[index_.product(r, c)];
  return M;
}

int MomentRelaxation::full_localizing_order(const Polynomial& g) const {
  return order_ - ceil_half(std::max(0, g.degree()));
}

Eigen::MatrixXd MomentRelaxation::localizing_matrix(const Polynomial& g, const std::vector<double>& y,
                                                    int max_order) const {
  const int full = full_localizing_order(g);
  const int k = max_order >= 0 && full >= 0 ? std::min(full, max_order) : full;
  if (k < 0) throw std::invalid_argument("localizing_matrix: constraint degree exceeds 2 * order");
  const int size = static_cast<int>(MonomialBasis::count(index_.basis().num_vars(), k));
  Eigen::MatrixXd L = Eigen::MatrixXd::Zero(size, size);
  for (const auto& [e, coef] : g.terms()) {
    const long gi = index_.index_of(e);
    for (int r = 0; r < size; ++r)
      for (int c = r; c < size; ++c) L(r, c) += coef * y[index_.product(index_.product(r, c), gi)];
  }
  return L.selfadjointView<Eigen::Upper>();
}

std::string ToString(RelaxationStatus s) {
  switch (s) {
    case RelaxationStatus::kSolved: return "solved";
    case RelaxationStatus::kInfeasible: return "infeasible";
    case RelaxationStatus::kUnbounded: return "unbounded";
    case RelaxationStatus::kSolverFailed: return "solver_failed";
    case RelaxationStatus::kInvalid: return "invalid";
  }
  return "unknown";
}

namespace {

int numerical_rank(const Eigen::MatrixXd& M, double tol) {
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(M);
  const auto ev = es.eigenvalues().cwiseAbs();
  const double top = ev.maxCoeff();
  if (top <= 0) return 0;
  int r = 0;
  for (Eigen::Index i = 0; i < ev.size(); ++i)
    if (ev[i] > tol * top) ++r;
  return r;
}

}  // namespace

std::vector<std::vector<double>> ExtractMinimizers(const Eigen::MatrixXd& M, const MonomialBasis& basis, int s,
                                                   double tol) {
  const int n = basis.num_vars();
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(M);
  const Eigen::VectorXd ev = es.eigenvalues();
  const double top = ev.cwiseAbs().maxCoeff();
  std::vector<int> keep;
  for (Eigen::Index i = 0; i < ev.size(); ++i)
    if (ev[i] > tol * top) keep.push_back(static_cast<int>(i));
  const int r = static_cast<int>(keep.size());
  if (r == 0) return {};
  Eigen::MatrixXd V(M.rows(), r);
  for (int j = 0; j < r; ++j) V.col(j) = es.eigenvectors().col(keep[j]) * std::sqrt(ev[keep[j]]);
  // Greedy choice of r independent rows (lowest degree first): the monomial basis w of the quotient.
  std::vector<int> chosen;
  Eigen::MatrixXd Q(r, 0);
  for (int row = 0; row < V.rows() && static_cast<int>(chosen.size()) < r; ++row) {
    Eigen::VectorXd v = V.row(row).transpose();
    for (int k = 0; k < Q.cols(); ++k) v -= Q.col(k).dot(v) * Q.col(k);
    if (v.norm() > 1e-6 * std::max(1.0, V.row(row).norm())) {
      Q.conservativeResize(Eigen::NoChange, Q.cols() + 1);
      Q.col(Q.cols() - 1) = v.normalized();
      chosen.push_back(row);
    }
  }
  if (static_cast<int>(chosen.size()) < r) return {};
  for (int row : chosen)
    if (degree_of(basis[row]) >= s) return {};  // x_i * w must stay inside the basis of degree <= s
  Eigen::MatrixXd W(r, r);
  for (int j = 0; j < r; ++j) W.row(j) = V.row(chosen[j]);
  const Eigen::MatrixXd U = V * W.inverse();  // rows of U at `chosen` form the identity
  std::vector<Eigen::MatrixXd> N(n, Eigen::MatrixXd(r, r));
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < r; ++j) {
      Exponents e = basis[chosen[j]];
      e[i]++;
      const long row = basis.index_of(e);
      if (row < 0) return {};
      N[i].row(j) = U.row(row);
    }
  }
  std::mt19937 rng(12345);
  std::uniform_real_distribution<double> dist(0.1, 1.0);
  Eigen::MatrixXd combo = Eigen::MatrixXd::Zero(r, r);
  double total = 0.0;
  std::vector<double> lambda(n);
  for (auto& l : lambda) total += (l = dist(rng));
  for (int i = 0; i < n; ++i) combo += (lambda[i] / total) * N[i];
  Eigen::RealSchur<Eigen::MatrixXd> schur(combo);
  const Eigen::MatrixXd& Qs = schur.matrixU();
  std::vector<std::vector<double>> points(r, std::vector<double>(n));
  for (int j = 0; j < r; ++j)
    for (int i = 0; i < n; ++i) points[j][i] = Qs.col(j).dot(N[i] * Qs.col(j));
  return points;
}

RelaxationResult SolveRelaxation(const RelaxationOptions& options, const PolyProblem& problem, sdp::SdpSolver& solver) {
  RelaxationResult result;
  std::string error;
  if (!options.IsValid(&error) || !problem.IsValid(&error)) {
    result.message = error;
    return result;
  }
  const int order = options.order == 0 ? problem.minimal_order() : options.order;
  result.order = order;
  if (order < problem.minimal_order()) {
    result.message = fmt::format("order {} is below the minimal order {}", order, problem.minimal_order());
    return result;
  }
  std::optional<MomentRelaxation> relaxation;
  try {
    relaxation.emplace(problem, order);
  } catch (const std::domain_error& e) {
    result.status = RelaxationStatus::kInfeasible;
    result.message = e.what();
    return result;
  }
  result.num_moments = relaxation->lmi().c.size();
  result.num_blocks = relaxation->lmi().blocks.size();
  result.sdp = solver.Solve(options.sdp, relaxation->lmi());
  const auto& sdp = result.sdp;
  const double sign = relaxation->objective_sign();
  switch (sdp.status) {
    case sdp::SdpStatus::kOptimal: break;
    case sdp::SdpStatus::kInfeasible: {
      // The backend's certificate test holds for moments up to 1 / infeasibility_tolerance; a rigorous
      // emptiness claim needs the a-priori moment bounds that the problem implies (a box or a ball).
      const auto cert = sdp::VerifyInfeasibility(relaxation->lmi(), sdp.X, MomentVariableBounds(problem, *relaxation));
      if (cert.verified()) {
        result.status = RelaxationStatus::kInfeasible;
        result.message = "the relaxation is infeasible (certificate verified), so the problem is infeasible";
      } else {
        result.status = RelaxationStatus::kSolverFailed;
        result.message = fmt::format("{} reports the relaxation infeasible, but the certificate does not verify "
                                     "({}); the problem is NOT declared infeasible (a box or a ball bounds the moments)",
                                     sdp.solver, cert.message);
      }
      return result;
    }
    case sdp::SdpStatus::kUnbounded:
      result.status = RelaxationStatus::kUnbounded;
      result.message = "the relaxation is unbounded (add a box or a ball to make the feasible set compact)";
      return result;
    default:
      result.status = RelaxationStatus::kSolverFailed;
      result.message = fmt::format("{} ended with {}: {}", sdp.solver, sdp::ToString(sdp.status), sdp.message);
      return result;
  }
  result.status = RelaxationStatus::kSolved;
  result.bound = sign * sdp.lower_bound;
  result.primal_value = sign * sdp.primal_value;
  const auto y = relaxation->moments(sdp.y);
  const int n = problem.num_vars;
  result.first_moments.assign(y.begin() + 1, y.begin() + 1 + n);

  // Flatness: rank M_s == rank M_{s-d} for some s in [max(d, 1), order].
  int d = 1;
  for (const auto& g : problem.inequalities) d = std::max(d, ceil_half(g.degree()));
  for (const auto& h : problem.equalities) d = std::max(d, ceil_half(h.degree()));
  for (int s = std::max(d, 1); s <= order && !result.flat; ++s) {
    const auto Ms = relaxation->moment_matrix(y, s);
    const int rs = numerical_rank(Ms, options.rank_tolerance);
    const int rlow = numerical_rank(relaxation->moment_matrix(y, s - d), options.rank_tolerance);
    if (rs != rlow) continue;
    MonomialBasis basis_s(n, s);
    auto points = ExtractMinimizers(Ms, basis_s, s, options.rank_tolerance);
    if (points.empty()) continue;
    // Accept the atoms only if they are feasible and attain the bound: then the bound is the global optimum.
    bool ok = true;
    for (const auto& x : points) {
      const double fx = problem.objective.evaluate(x);
      const double scale = std::max(1.0, std::abs(result.bound));
      if (std::abs(fx - result.bound) > options.extraction_tolerance * scale * 10) ok = false;
      for (const auto& g : problem.inequalities)
        if (g.evaluate(x) < -options.extraction_tolerance * std::max(1.0, g.max_abs_coefficient())) ok = false;
      for (const auto& h : problem.equalities)
        if (std::abs(h.evaluate(x)) > options.extraction_tolerance * std::max(1.0, h.max_abs_coefficient())) ok = false;
      for (std::size_t i = 0; i < problem.box.size(); ++i)
        if (x[i] < problem.box[i].first - 1e-6 || x[i] > problem.box[i].second + 1e-6) ok = false;
    }
    if (!ok) continue;
    result.flat = true;
    result.rank = rs;
    result.minimizers = std::move(points);
  }
  result.message = result.flat ? "global optimum certified by flat extension" : "bound (not certified as the optimum)";
  return result;
}

}  // namespace hw::pop
