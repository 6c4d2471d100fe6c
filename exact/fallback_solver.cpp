#include "exact/fallback_solver.hpp"

#include <utility>

namespace hw::exact {
namespace {

bool Final(LpStatus status) {
  return status == LpStatus::kOptimal || status == LpStatus::kCutoff || status == LpStatus::kInfeasible;
}

}  // namespace

FallbackSolver::FallbackSolver(std::string name, std::unique_ptr<LpSolver> first, std::unique_ptr<LpSolver> second)
    : name_(std::move(name)), first_(std::move(first)), second_(std::move(second)) {}

LpResult FallbackSolver::Solve(const LpProblem& problem, const LpBasis& warm, const LpSolveOptions& options) {
  LpResult first = first_->Solve(problem, warm, options);
  if (Final(first.status)) return first;
  LpResult second = second_->Solve(problem, warm, options);
  // Neither finished: keep the first's answer (its duals still certify a bound, only a looser one).
  LpResult& kept = Final(second.status) ? second : first;
  kept.message = first.message + (Final(second.status) ? "; solved by " : "; then ") + second_->name() +
                 (second.message.empty() ? "" : ": " + second.message);
  kept.iterations = first.iterations + second.iterations;
  kept.seconds = first.seconds + second.seconds;
  return kept;
}

}  // namespace hw::exact
