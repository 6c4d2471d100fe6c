#include "exact/clp_solver.hpp"

#include <chrono>

#include <ClpSimplex.hpp>
#include <CoinPackedMatrix.hpp>

namespace hw::exact {
namespace {

CoinPackedMatrix ToColumnMatrix(const LpProblem& p) {
  std::vector<int> rows, cols;
  std::vector<double> values;
  rows.reserve(p.entries.size());
  cols.reserve(p.entries.size());
  values.reserve(p.entries.size());
  for (const auto& e : p.entries) {
    rows.push_back(e.row);
    cols.push_back(e.col);
    values.push_back(e.value);
  }
  // Duplicate (row, col) entries are summed, as the certificate sums them.
  CoinPackedMatrix m(true, rows.data(), cols.data(), values.data(), static_cast<CoinBigIndex>(values.size()));
  m.setDimensions(p.num_rows(), p.num_cols());
  return m;
}

LpStatus StatusOf(const ClpSimplex& model) {
  switch (model.status()) {
    case 0: return LpStatus::kOptimal;
    case 1: return LpStatus::kInfeasible;
    case 2: return LpStatus::kUnbounded;
    case 3: return LpStatus::kIterationLimit;
    default: return LpStatus::kFailed;
  }
}

}  // namespace

LpResult ClpSolver::Solve(const LpProblem& problem, const LpBasis& warm, const LpSolveOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  LpResult result;
  ClpSimplex model;
  model.setLogLevel(0);
  model.messageHandler()->setLogLevel(0);
  const CoinPackedMatrix matrix = ToColumnMatrix(problem);
  model.loadProblem(matrix, problem.col_lo.data(), problem.col_hi.data(), problem.obj.data(), problem.row_lo.data(),
                    problem.row_hi.data());
  model.setPrimalTolerance(options.primal_tolerance);
  model.setDualTolerance(options.dual_tolerance);
  model.setMaximumSeconds(options.time_limit_seconds);
  const std::size_t shape = static_cast<std::size_t>(problem.num_cols() + problem.num_rows());
  if (warm.status.size() == shape) {
    model.copyinStatus(warm.status.data());
    result.warm_started = true;
  }
  model.dual(0);
  if (model.status() != 0 && model.status() != 1) model.primal(1);  // the dual simplex stalled: try the primal
  result.status = StatusOf(model);
  result.iterations = model.numberIterations();
  result.objective = model.objectiveValue();
  const double* x = model.primalColumnSolution();
  const double* y = model.dualRowSolution();
  result.primal.assign(x, x + problem.num_cols());
  result.duals.assign(y, y + problem.num_rows());
  const unsigned char* status = model.statusArray();
  if (status) result.basis.status.assign(status, status + shape);
  if (result.status != LpStatus::kOptimal)
    result.message = "CLP status " + std::to_string(model.status()) + "." + std::to_string(model.secondaryStatus());
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace hw::exact
