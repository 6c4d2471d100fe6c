#include "exact/glpk_solver.hpp"

#include <chrono>
#include <cmath>
#include <memory>

#include <glpk.h>

namespace hw::exact {
namespace {

struct ProblemDeleter {
  void operator()(glp_prob* p) const { glp_delete_prob(p); }
};
using GlpkProblem = std::unique_ptr<glp_prob, ProblemDeleter>;

// GLPK's bound kind for lo <= x <= hi (either side may be infinite).
int BoundKind(double lo, double hi) {
  const bool has_lo = std::isfinite(lo), has_hi = std::isfinite(hi);
  if (has_lo && has_hi) return lo == hi ? GLP_FX : GLP_DB;
  if (has_lo) return GLP_LO;
  if (has_hi) return GLP_UP;
  return GLP_FR;
}

GlpkProblem Load(const LpProblem& p) {
  glp_term_out(GLP_OFF);  // GLPK prints scaling and basis notes on stdout otherwise
  GlpkProblem lp(glp_create_prob());
  glp_set_obj_dir(lp.get(), GLP_MIN);
  glp_add_rows(lp.get(), p.num_rows());
  glp_add_cols(lp.get(), p.num_cols());
  for (int i = 0; i < p.num_rows(); ++i)
    glp_set_row_bnds(lp.get(), i + 1, BoundKind(p.row_lo[i], p.row_hi[i]), std::isfinite(p.row_lo[i]) ? p.row_lo[i] : 0.0,
                     std::isfinite(p.row_hi[i]) ? p.row_hi[i] : 0.0);
  for (int j = 0; j < p.num_cols(); ++j) {
    glp_set_col_bnds(lp.get(), j + 1, BoundKind(p.col_lo[j], p.col_hi[j]), p.col_lo[j], p.col_hi[j]);
    glp_set_obj_coef(lp.get(), j + 1, p.obj[j]);
  }
  // GLPK forbids duplicate (row, col) entries; the certificate sums them, so sum them here too.
  std::vector<std::vector<std::pair<int, double>>> by_col(p.num_cols());
  for (const auto& e : p.entries) {
    auto& col = by_col[e.col];
    bool merged = false;
    for (auto& [row, value] : col)
      if (row == e.row) value += e.value, merged = true;
    if (!merged) col.emplace_back(e.row, e.value);
  }
  std::vector<int> index;
  std::vector<double> value;
  for (int j = 0; j < p.num_cols(); ++j) {
    index.assign(1, 0);
    value.assign(1, 0.0);  // GLPK arrays are 1-based
    for (const auto& [row, v] : by_col[j]) index.push_back(row + 1), value.push_back(v);
    glp_set_mat_col(lp.get(), j + 1, static_cast<int>(index.size()) - 1, index.data(), value.data());
  }
  return lp;
}

LpStatus StatusOf(glp_prob* lp, int ret) {
  if (ret != 0 && ret != GLP_ETMLIM && ret != GLP_EITLIM) return LpStatus::kFailed;
  switch (glp_get_status(lp)) {
    case GLP_OPT: return LpStatus::kOptimal;
    case GLP_NOFEAS: return LpStatus::kInfeasible;
    case GLP_UNBND: return LpStatus::kUnbounded;
    default: return ret == 0 ? LpStatus::kFailed : LpStatus::kIterationLimit;
  }
}

}  // namespace

LpResult GlpkSolver::Solve(const LpProblem& problem, const LpBasis& warm, const LpSolveOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  LpResult result;
  GlpkProblem lp = Load(problem);
  const int n = problem.num_cols(), m = problem.num_rows();
  glp_scale_prob(lp.get(), GLP_SF_AUTO);
  if (warm.status.size() == static_cast<std::size_t>(n + m)) {
    for (int j = 0; j < n; ++j) glp_set_col_stat(lp.get(), j + 1, warm.status[j]);
    for (int i = 0; i < m; ++i) glp_set_row_stat(lp.get(), i + 1, warm.status[n + i]);
    result.warm_started = true;
  } else {
    glp_adv_basis(lp.get(), 0);
  }
  glp_smcp parm;
  glp_init_smcp(&parm);
  parm.msg_lev = GLP_MSG_OFF;
  parm.meth = GLP_DUALP;
  parm.tol_bnd = options.primal_tolerance;
  parm.tol_dj = options.dual_tolerance;
  parm.tm_lim = static_cast<int>(std::min(options.time_limit_seconds * 1000.0, 2.0e9));
  int ret = glp_simplex(lp.get(), &parm);
  if (ret == GLP_EBADB || ret == GLP_ESING || ret == GLP_ECOND) {  // the warm basis does not fit: start afresh
    glp_adv_basis(lp.get(), 0);
    result.warm_started = false;
    ret = glp_simplex(lp.get(), &parm);
  }
  result.status = StatusOf(lp.get(), ret);
  result.objective = glp_get_obj_val(lp.get());
  result.primal.resize(n);
  result.duals.resize(m);
  result.basis.status.resize(n + m);
  for (int j = 0; j < n; ++j) {
    result.primal[j] = glp_get_col_prim(lp.get(), j + 1);
    result.basis.status[j] = static_cast<std::uint8_t>(glp_get_col_stat(lp.get(), j + 1));
  }
  for (int i = 0; i < m; ++i) {
    result.duals[i] = glp_get_row_dual(lp.get(), i + 1);
    result.basis.status[n + i] = static_cast<std::uint8_t>(glp_get_row_stat(lp.get(), i + 1));
  }
  result.iterations = glp_get_it_cnt(lp.get());
  if (result.status != LpStatus::kOptimal)
    result.message = "GLPK simplex returned " + std::to_string(ret) + ", status " + std::to_string(glp_get_status(lp.get()));
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace hw::exact
