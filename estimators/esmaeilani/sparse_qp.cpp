#include "estimators/esmaeilani/sparse_qp.hpp"

#include <IpIpoptApplication.hpp>
#include <IpSolveStatistics.hpp>
#include <IpTNLP.hpp>

#include <fmt/format.h>

namespace hw::esmaeilani {
namespace {

using Ipopt::Index;
using Ipopt::Number;

// The QP as an Ipopt TNLP: constant Hessian and constant constraint Jacobian.
class QpTnlp : public Ipopt::TNLP {
 public:
  QpTnlp(const SparseQp& qp, Eigen::VectorXd* x) : qp_(qp), x_(x) {
    lower_ = qp.H.triangularView<Eigen::Lower>();
    lower_.makeCompressed();
    a_ = qp.A;
    a_.makeCompressed();
  }
  bool get_nlp_info(Index& n, Index& m, Index& nnz_jac, Index& nnz_h, IndexStyleEnum& style) override {
    n = static_cast<Index>(qp_.c.size());
    m = static_cast<Index>(qp_.A.rows());
    nnz_jac = static_cast<Index>(a_.nonZeros());
    nnz_h = static_cast<Index>(lower_.nonZeros());
    style = C_STYLE;
    return true;
  }
  bool get_bounds_info(Index n, Number* xl, Number* xu, Index m, Number* gl, Number* gu) override {
    for (Index i = 0; i < n; ++i) xl[i] = qp_.var_lower[i], xu[i] = qp_.var_upper[i];
    for (Index i = 0; i < m; ++i) gl[i] = qp_.row_lower[i], gu[i] = qp_.row_upper[i];
    return true;
  }
  bool get_starting_point(Index n, bool init_x, Number* x, bool, Number*, Number*, Index, bool, Number*) override {
    if (init_x)
      for (Index i = 0; i < n; ++i) x[i] = (*x_)[i];
    return true;
  }
  bool eval_f(Index n, const Number* x, bool, Number& obj) override {
    Eigen::Map<const Eigen::VectorXd> v(x, n);
    obj = 0.5 * v.dot(qp_.H.selfadjointView<Eigen::Lower>() * v) + qp_.c.dot(v);
    return true;
  }
  bool eval_grad_f(Index n, const Number* x, bool, Number* g) override {
    Eigen::Map<const Eigen::VectorXd> v(x, n);
    Eigen::Map<Eigen::VectorXd>(g, n) = qp_.H.selfadjointView<Eigen::Lower>() * v + qp_.c;
    return true;
  }
  bool eval_g(Index n, const Number* x, bool, Index m, Number* g) override {
    if (m == 0) return true;
    Eigen::Map<const Eigen::VectorXd> v(x, n);
    Eigen::Map<Eigen::VectorXd>(g, m) = a_ * v;
    return true;
  }
  bool eval_jac_g(Index, const Number*, bool, Index, Index, Index* irow, Index* jcol, Number* values) override {
    Index k = 0;
    for (int col = 0; col < a_.outerSize(); ++col)
      for (Eigen::SparseMatrix<double>::InnerIterator it(a_, col); it; ++it, ++k) {
        if (values) {
          values[k] = it.value();
        } else {
          irow[k] = static_cast<Index>(it.row());
          jcol[k] = static_cast<Index>(it.col());
        }
      }
    return true;
  }
  bool eval_h(Index, const Number*, bool, Number obj_factor, Index, const Number*, bool, Index, Index* irow,
              Index* jcol, Number* values) override {
    Index k = 0;
    for (int col = 0; col < lower_.outerSize(); ++col)
      for (Eigen::SparseMatrix<double>::InnerIterator it(lower_, col); it; ++it, ++k) {
        if (values) {
          values[k] = obj_factor * it.value();
        } else {
          irow[k] = static_cast<Index>(it.row());
          jcol[k] = static_cast<Index>(it.col());
        }
      }
    return true;
  }
  void finalize_solution(Ipopt::SolverReturn status, Index n, const Number* x, const Number*, const Number*, Index,
                         const Number*, const Number*, Number obj, const Ipopt::IpoptData*,
                         Ipopt::IpoptCalculatedQuantities*) override {
    status_ = status;
    objective_ = obj;
    for (Index i = 0; i < n; ++i) (*x_)[i] = x[i];
  }
  Ipopt::SolverReturn status_ = Ipopt::INTERNAL_ERROR;
  double objective_ = 0.0;

 private:
  const SparseQp& qp_;
  Eigen::VectorXd* x_;
  Eigen::SparseMatrix<double> lower_, a_;
};

}  // namespace

QpSummary SolveQp(const QpOptions& options, const SparseQp& qp, Eigen::VectorXd* x) {
  if (options.backend == QpOptions::Backend::kCgal) return SolveQpCgal(options, qp, x);
  QpSummary summary;
  Ipopt::SmartPtr<QpTnlp> tnlp = new QpTnlp(qp, x);
  Ipopt::SmartPtr<Ipopt::IpoptApplication> app = IpoptApplicationFactory();
  app->Options()->SetIntegerValue("print_level", options.print_level);
  app->Options()->SetStringValue("sb", "yes");
  app->Options()->SetNumericValue("tol", options.tolerance);
  app->Options()->SetIntegerValue("max_iter", options.max_iterations);
  app->Options()->SetStringValue("hessian_constant", "yes");
  app->Options()->SetStringValue("jac_c_constant", "yes");
  app->Options()->SetStringValue("jac_d_constant", "yes");
  app->Options()->SetStringValue("mu_strategy", "adaptive");
  if (app->Initialize() != Ipopt::Solve_Succeeded) {
    summary.message = "Ipopt failed to initialise";
    return summary;
  }
  const Ipopt::ApplicationReturnStatus status = app->OptimizeTNLP(Ipopt::GetRawPtr(tnlp));
  summary.iterations = Ipopt::IsValid(app->Statistics()) ? app->Statistics()->IterationCount() : 0;
  summary.objective = tnlp->objective_;
  summary.solved = status == Ipopt::Solve_Succeeded || status == Ipopt::Solved_To_Acceptable_Level;
  summary.infeasible = status == Ipopt::Infeasible_Problem_Detected;
  summary.message = fmt::format("Ipopt status {}", static_cast<int>(status));
  return summary;
}

}  // namespace hw::esmaeilani
