#include "sdp/sdp_solver.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <mutex>
#include <tuple>
#include <stdexcept>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "sdp/csdp_backend.hpp"
#include "sdp/dsdp_backend.hpp"
#include "sdp/sdpa_backend.hpp"

extern "C" void openblas_set_num_threads(int);

namespace hw::sdp {

bool SdpOptions::IsValid(std::string* error) const {
  auto fail = [&](std::string m) {
    if (error) *error = std::move(m);
    return false;
  };
  if (!(gap_tolerance > 0 && gap_tolerance < 1)) return fail("gap_tolerance must lie in (0, 1)");
  if (!(feasibility_tolerance > 0 && feasibility_tolerance < 1)) return fail("feasibility_tolerance must lie in (0, 1)");
  if (max_iterations < 1) return fail("max_iterations must be >= 1");
  if (!(acceptable_gap >= gap_tolerance && acceptable_gap < 1)) return fail("acceptable_gap must lie in [gap_tolerance, 1)");
  for (std::size_t i = 0; i < initial_y.size(); ++i)
    if (!std::isfinite(initial_y[i])) return fail(fmt::format("initial_y[{}] is not finite", i));
  return true;
}

std::string ToString(SdpStatus s) {
  switch (s) {
    case SdpStatus::kOptimal: return "optimal";
    case SdpStatus::kInfeasible: return "infeasible";
    case SdpStatus::kUnbounded: return "unbounded";
    case SdpStatus::kInaccurate: return "inaccurate";
    case SdpStatus::kIterationLimit: return "iteration_limit";
    case SdpStatus::kNumericalTrouble: return "numerical_trouble";
    case SdpStatus::kInvalidProblem: return "invalid_problem";
  }
  return "unknown";
}

double InnerProduct(const std::vector<Entry>& F, const std::vector<Eigen::MatrixXd>& X) {
  double s = 0.0;
  for (const auto& e : F) s += e.value * X[e.block](e.row, e.col) * (e.row == e.col ? 1.0 : 2.0);
  return s;
}

double InfeasibilityResidual(const LmiProblem& problem, const std::vector<Eigen::MatrixXd>& X) {
  const double inf = std::numeric_limits<double>::infinity();
  if (X.size() != problem.blocks.size()) return inf;
  double scale = 0.0;
  for (const auto& B : X) scale = std::max(scale, B.cwiseAbs().maxCoeff());
  for (std::size_t b = 0; b < X.size(); ++b) {
    const auto& B = X[b];
    if (B.rows() == 0) continue;
    // Diagonal (LP) blocks are stored as square matrices; their eigenvalues are the diagonal (an eigen-solve of
    // a 4000-row LP block took minutes).
    const double lmin = problem.blocks[b].kind == BlockSpec::Kind::kDiagonal
                            ? B.diagonal().minCoeff()
                            : Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(B, Eigen::EigenvaluesOnly).eigenvalues()(0);
    if (lmin < -1e-10 * std::max(scale, 1e-300)) return inf;
  }
  const double f0 = InnerProduct(problem.F[0], X);
  if (!(f0 > 0)) return inf;
  double sum = 0.0;
  for (std::size_t i = 1; i < problem.F.size(); ++i) sum += std::abs(InnerProduct(problem.F[i], X));
  return sum / f0;
}

void ConfirmInfeasibility(const SdpOptions& options, const LmiProblem& problem, const std::vector<Eigen::MatrixXd>& X,
                          SdpSummary* s) {
  const double r = InfeasibilityResidual(problem, X);
  s->details["infeasibility_residual"] = std::isfinite(r) ? r : -1.0;
  if (r <= options.infeasibility_tolerance) {
    s->status = SdpStatus::kInfeasible;
    s->message += fmt::format(" (infeasibility certificate checked: sum|F_i.X| / F_0.X = {:.2e})", r);
  } else {
    s->status = SdpStatus::kNumericalTrouble;
    s->message += fmt::format(" (claimed infeasible, but the certificate fails: residual {:.2e})", r);
  }
}

double UnboundednessResidual(const LmiProblem& problem, const std::vector<double>& d) {
  const double inf = std::numeric_limits<double>::infinity();
  if (static_cast<int>(d.size()) != problem.num_vars()) return inf;
  double norm = 0.0;
  for (double v : d) norm += v * v;
  norm = std::sqrt(norm);
  if (!(norm > 0) || !std::isfinite(norm)) return inf;
  double cd = 0.0;
  for (std::size_t i = 0; i < d.size(); ++i) cd += problem.c[i] * d[i] / norm;
  if (!(cd < 0)) return inf;
  double worst = 0.0;
  for (std::size_t b = 0; b < problem.blocks.size(); ++b) {
    const int n = problem.blocks[b].size;
    Eigen::MatrixXd S = Eigen::MatrixXd::Zero(n, n);
    for (std::size_t i = 1; i < problem.F.size(); ++i)
      for (const auto& e : problem.F[i])
        if (e.block == static_cast<int>(b)) {
          S(e.row, e.col) += e.value * d[i - 1] / norm;
          if (e.row != e.col) S(e.col, e.row) += e.value * d[i - 1] / norm;
        }
    worst = std::min(worst, problem.blocks[b].kind == BlockSpec::Kind::kDiagonal
                                ? S.diagonal().minCoeff()
                                : Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(S, Eigen::EigenvaluesOnly).eigenvalues()(0));
  }
  return -worst / -cd;
}

void ResolveInfeasibilityClaim(const SdpOptions& options, const LmiProblem& problem, SdpSummary* s) {
  const double r_inf = InfeasibilityResidual(problem, s->X);
  const double r_unb = UnboundednessResidual(problem, s->y);
  s->details["infeasibility_residual"] = std::isfinite(r_inf) ? r_inf : -1.0;
  s->details["unboundedness_residual"] = std::isfinite(r_unb) ? r_unb : -1.0;
  const double inf = std::numeric_limits<double>::infinity();
  if (r_inf <= options.infeasibility_tolerance) {
    s->status = SdpStatus::kInfeasible;
    s->lower_bound = s->primal_value = inf;
    s->message += fmt::format(" -> infeasible: X certifies it (sum|F_i.X| / F_0.X = {:.2e})", r_inf);
  } else if (r_unb <= options.infeasibility_tolerance) {
    s->status = SdpStatus::kUnbounded;
    s->lower_bound = s->primal_value = -inf;
    s->message += fmt::format(" -> unbounded: y is a descent ray (lambda_min^- / -c'd = {:.2e})", r_unb);
  } else {
    s->status = SdpStatus::kNumericalTrouble;
    s->message += " -> neither an infeasibility certificate nor a descent ray could be checked";
  }
}

void AcceptNearOptimal(const SdpOptions& options, SdpSummary* s) {
  if (s->status != SdpStatus::kInaccurate) return;
  if (s->relative_gap <= options.acceptable_gap && s->primal_infeasibility <= options.acceptable_gap &&
      s->dual_infeasibility <= options.acceptable_gap) {
    s->status = SdpStatus::kOptimal;
    s->message += " (accepted: gap and infeasibilities within acceptable_gap)";
  }
}

double RelativeGap(double primal, double dual) {
  return std::abs(primal - dual) / std::max(1.0, 0.5 * (std::abs(primal) + std::abs(dual)));
}

// Solves run in parallel in our own job pool: BLAS (OpenBLAS; Debian's libblas.so.3 alternative forwards
// to the same libopenblas.so.0, so CSDP's -lblas, SDPA's -lopenblas and Ipopt's MUMPS share one setting)
// gets one thread, so concurrent solves never oversubscribe the cores and the arithmetic does not depend on
// the core count. Process-wide, set once.
void UseSingleThreadedBlas() {
  static std::once_flag once;
  std::call_once(once, [] { openblas_set_num_threads(1); });
}

namespace {

// Sums duplicate entries and drops zeros, matrix by matrix.
std::vector<Entry> Canonical(const std::vector<Entry>& entries) {
  std::map<std::tuple<int, int, int>, double> sum;
  for (const auto& e : entries) sum[{e.block, std::min(e.row, e.col), std::max(e.row, e.col)}] += e.value;
  std::vector<Entry> out;
  for (const auto& [key, v] : sum)
    if (v != 0.0) out.push_back({std::get<0>(key), std::get<1>(key), std::get<2>(key), v});
  return out;
}

// No variables left: min 0 s.t. -F_0 >= 0.
SdpSummary DecideConstantLmi(const LmiProblem& p) {
  SdpSummary s;
  s.status = SdpStatus::kOptimal;
  double worst = 0.0;
  for (std::size_t b = 0; b < p.blocks.size(); ++b) {
    const int n = p.blocks[b].size;
    Eigen::MatrixXd S = Eigen::MatrixXd::Zero(n, n);
    for (const auto& e : p.F[0])
      if (e.block == static_cast<int>(b)) {
        S(e.row, e.col) -= e.value;
        if (e.row != e.col) S(e.col, e.row) -= e.value;
      }
    Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(S);
    s.Z.push_back(S);
    s.X.push_back(Eigen::MatrixXd::Zero(n, n));
    if (eig.eigenvalues()(0) < worst) worst = eig.eigenvalues()(0);
  }
  if (worst < 0.0) {
    // X = v v^T on the most negative eigenvector: F_0 . X = -lambda_min > 0 and there is no F_i to cancel it.
    for (std::size_t b = 0; b < p.blocks.size(); ++b) {
      Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(s.Z[b]);
      if (eig.eigenvalues()(0) == worst) {
        const Eigen::VectorXd v = eig.eigenvectors().col(0);
        s.X[b] = v * v.transpose();
        break;
      }
    }
    s.status = SdpStatus::kInfeasible;
    s.lower_bound = std::numeric_limits<double>::infinity();
    s.primal_value = std::numeric_limits<double>::infinity();
  }
  s.message = fmt::format("no variable enters the LMI: decided by the smallest eigenvalue of -F_0 ({:.3e})", worst);
  return s;
}

}  // namespace

SdpSummary SolveAsBackend(const std::string& name, const SdpOptions& options, const LmiProblem& problem,
                          const CanonicalSolve& solve) {
  SdpSummary out = SolveCanonical(options, problem, solve);
  out.solver = name;
  if (!options.keep_dual_matrix) {
    out.X.clear();
    out.Z.clear();
  }
  return out;
}

SdpSummary SolveCanonical(const SdpOptions& options, const LmiProblem& problem, const CanonicalSolve& solve) {
  UseSingleThreadedBlas();
  std::string error;
  if (options.IsValid(&error) && problem.IsValid(&error) && !options.initial_y.empty() &&
      static_cast<int>(options.initial_y.size()) != problem.num_vars())
    error = fmt::format("initial_y has {} values for {} variables", options.initial_y.size(), problem.num_vars());
  if (!error.empty()) {
    SdpSummary out;
    out.status = SdpStatus::kInvalidProblem;
    out.message = error;
    return out;
  }
  LmiProblem reduced;
  reduced.blocks = problem.blocks;
  reduced.objective_offset = problem.objective_offset;
  reduced.F.push_back(Canonical(problem.F[0]));
  std::vector<int> kept;
  int dropped_with_cost = -1;
  for (int i = 1; i <= problem.num_vars(); ++i) {
    auto Fi = Canonical(problem.F[i]);
    if (Fi.empty()) {
      if (problem.c[i - 1] != 0.0 && dropped_with_cost < 0) dropped_with_cost = i;
      continue;
    }
    kept.push_back(i - 1);
    reduced.c.push_back(problem.c[i - 1]);
    reduced.F.push_back(std::move(Fi));
  }
  SdpOptions reduced_options = options;
  if (!options.initial_y.empty()) {
    reduced_options.initial_y.clear();
    for (int k : kept) reduced_options.initial_y.push_back(options.initial_y[k]);
  }
  SdpSummary out = reduced.num_vars() == 0 ? DecideConstantLmi(reduced) : solve(reduced_options, reduced);
  if (reduced.num_vars() == 0) {
    out.lower_bound += problem.objective_offset;
    out.primal_value += problem.objective_offset;
  }
  if (!out.y.empty() || reduced.num_vars() == 0) {
    std::vector<double> y(problem.num_vars(), 0.0);
    for (std::size_t j = 0; j < kept.size() && j < out.y.size(); ++j) y[kept[j]] = out.y[j];
    out.y = std::move(y);
  }
  const int removed = problem.num_vars() - reduced.num_vars();
  out.details["removed_variables"] = removed;
  if (dropped_with_cost > 0 && out.status != SdpStatus::kInfeasible && out.status != SdpStatus::kInvalidProblem) {
    if (out.status == SdpStatus::kOptimal || out.status == SdpStatus::kUnbounded) {
      out.status = SdpStatus::kUnbounded;
      out.lower_bound = out.primal_value = -std::numeric_limits<double>::infinity();
    }
    out.message += fmt::format("; variable {} has F_i = 0 but c_i != 0, so the objective is unbounded below "
                               "wherever the LMI is feasible",
                               dropped_with_cost);
  }
  return out;
}

std::unique_ptr<SdpSolver> MakeSolver(const std::string& name) {
  if (name == "csdp") return std::make_unique<CsdpSolver>();
  if (name == "sdpa") return std::make_unique<SdpaSolver>();
  if (name == "dsdp") return std::make_unique<DsdpSolver>();
  std::string error;
  ValidSolverName(name, &error);
  throw std::invalid_argument(error);
}

std::vector<std::string> AvailableSolvers() { return {"csdp", "sdpa", "dsdp"}; }

bool ValidSolverName(const std::string& name, std::string* error) {
  const auto names = AvailableSolvers();
  if (std::find(names.begin(), names.end(), name) != names.end()) return true;
  if (error) *error = fmt::format("solver '{}' unknown; expected {}", name, fmt::join(names, ", "));
  return false;
}

}  // namespace hw::sdp
