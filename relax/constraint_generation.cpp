#include "relax/constraint_generation.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <optional>
#include <set>

#include <fmt/format.h>

namespace hw::relax {

bool ConstraintGenerationOptions::IsValid(std::string* error) const {
  auto fail = [&](std::string m) {
    if (error) *error = std::move(m);
    return false;
  };
  if (order < 0) return fail("order must be >= 0");
  if (max_rounds < 1) return fail("max_rounds must be >= 1");
  if (add_per_round < 1) return fail("add_per_round must be >= 1");
  if (!(violation_tolerance > 0)) return fail("violation_tolerance must be > 0");
  if (!verify.IsValid(error)) return false;
  return sdp.IsValid(error);
}

ConstraintGenerationResult SolveWithConstraintGeneration(const ConstraintGenerationOptions& options,
                                                         const PolyProblem& core,
                                                         const std::vector<Polynomial>& candidates,
                                                         std::vector<int> initial, sdp::SdpSolver& solver,
                                                         const std::function<void(const std::vector<int>&)>& on_round,
                                                         sdp::SdpSolver* fallback) {
  ConstraintGenerationResult result;
  std::string error;
  if (!options.IsValid(&error) || !core.IsValid(&error)) {
    result.message = error;
    return result;
  }
  std::set<int> working(initial.begin(), initial.end());
  int order = options.order;
  {
    PolyProblem all = core;
    for (const auto& g : candidates) all.inequalities.push_back(g);
    order = std::max(order == 0 ? all.minimal_order() : order, all.minimal_order());
  }
  const bool verify = options.verify.enabled;
  sdp::SdpOptions sdp_options = options.sdp;
  if (verify) sdp_options.keep_dual_matrix = true;
  // Verifies the bound of the final round (a perturbed re-solve may be needed; intermediate rounds' bounds
  // are never reported, so they are not verified).
  auto verify_bound = [&](const PolyProblem& problem, const MomentRelaxation& relaxation, const sdp::SdpSummary& sdp,
                          sdp::SdpSolver& used) {
    const double sign = relaxation.objective_sign();
    result.float_bound = sign * sdp.lower_bound;
    if (!verify) return;
    result.verification = sdp::VerifyOptimalSolve(options.verify, sdp_options, relaxation.lmi(),
                                                  MomentVariableBounds(problem, relaxation), sdp, used);
    result.verification.float_bound = result.float_bound;
    if (result.verification.verified()) {
      result.bound = sign * result.verification.bound;
    } else {
      result.message += "; " + result.verification.message;
    }
  };
  // The last round whose LMI was solved: its bound is valid for the full set too (it relaxes a subset of the
  // inequalities), so a later round that the solver fails on falls back to it instead of losing it.
  struct SolvedRound {
    PolyProblem problem;
    std::unique_ptr<MomentRelaxation> relaxation;
    sdp::SdpSummary sdp;
    sdp::SdpSolver* used = nullptr;
    std::vector<int> working;
    double max_violation = 0.0;
  };
  std::optional<SolvedRound> last_solved;
  auto fall_back = [&](const std::string& why) {
    if (!last_solved) return false;
    const auto& r = *last_solved;
    const double sign = r.relaxation->objective_sign();
    result.status = RelaxationStatus::kSolved;
    result.tight = false;
    result.bound = sign * r.sdp.lower_bound;
    result.primal_value = sign * r.sdp.primal_value;
    result.max_violation = r.max_violation;
    result.working_set = r.working;
    result.message = fmt::format("{}; the bound of the last solved round ({} of {} data constraints) is reported: "
                                 "valid, possibly looser than the full relaxation's",
                                 why, r.working.size(), candidates.size());
    verify_bound(r.problem, *r.relaxation, r.sdp, *r.used);
    return true;
  };
  for (int round = 1; round <= options.max_rounds; ++round) {
    result.rounds = round;
    PolyProblem problem = core;
    for (int i : working) problem.inequalities.push_back(candidates[i]);
    MomentRelaxation relaxation(problem, order);
    result.num_moments = relaxation.lmi().c.size();
    result.num_blocks = relaxation.lmi().blocks.size();
    auto sdp = solver.Solve(sdp_options, relaxation.lmi());
    sdp::SdpSolver* used = &solver;
    if (fallback && !sdp.decided()) {
      const std::string first = sdp.message;
      result.solve_seconds += sdp.setup_seconds + sdp.solve_seconds;
      sdp = fallback->Solve(sdp_options, relaxation.lmi());
      sdp.message += " [after " + first + "]";
      used = fallback;
    }
    result.solve_seconds += sdp.setup_seconds + sdp.solve_seconds;
    result.sdp_iterations += sdp.iterations;
    result.working_set.assign(working.begin(), working.end());
    if (verify && sdp.status == sdp::SdpStatus::kInfeasible) {
      // An emptiness claim stands only on a verified certificate; the other backend gets one chance to give one.
      result.verification = sdp::VerifyInfeasibility(relaxation.lmi(), sdp.X, MomentVariableBounds(problem, relaxation));
      if (!result.verification.verified() && fallback && used != fallback) {
        auto second = fallback->Solve(sdp_options, relaxation.lmi());
        result.solve_seconds += second.setup_seconds + second.solve_seconds;
        if (second.status == sdp::SdpStatus::kInfeasible) {
          auto v = sdp::VerifyInfeasibility(relaxation.lmi(), second.X, MomentVariableBounds(problem, relaxation));
          v.seconds += result.verification.seconds;
          if (v.verified()) sdp = std::move(second);
          result.verification = v;
        }
      }
      if (!result.verification.verified()) {
        result.last_sdp = sdp;
        const std::string why = fmt::format("relaxation reported infeasible, but {}: the set is NOT declared empty",
                                            result.verification.message);
        result.verification = {};
        if (fall_back(why)) return result;
        result.status = RelaxationStatus::kSolverFailed;
        result.message = why;
        return result;
      }
    }
    result.last_sdp = sdp;
    if (sdp.status == sdp::SdpStatus::kInfeasible) {
      result.status = RelaxationStatus::kInfeasible;
      result.message = fmt::format("relaxation with {} of {} data constraints is infeasible: the set is empty",
                                   working.size(), candidates.size());
      return result;
    }
    if (sdp.status == sdp::SdpStatus::kUnbounded) {
      result.status = RelaxationStatus::kUnbounded;
      result.message = "relaxation unbounded: add a box";
      return result;
    }
    if (sdp.status != sdp::SdpStatus::kOptimal) {
      const std::string why = fmt::format("round {}: {}: {} ({})", round, sdp.solver, sdp::ToString(sdp.status),
                                          sdp.message);
      if (fall_back(why)) return result;
      result.status = RelaxationStatus::kSolverFailed;
      result.message = why;
      return result;
    }
    const double sign = relaxation.objective_sign();
    result.status = RelaxationStatus::kSolved;
    result.bound = sign * sdp.lower_bound;
    result.primal_value = sign * sdp.primal_value;
    const auto y = relaxation.moments(sdp.y);
    result.first_moments.assign(y.begin() + 1, y.begin() + 1 + core.num_vars);

    // Check every omitted candidate at the returned moments.
    std::vector<std::pair<double, int>> violated;
    double worst = 0.0;
    for (int i = 0; i < static_cast<int>(candidates.size()); ++i) {
      if (working.count(i)) continue;
      const Eigen::MatrixXd L = relaxation.localizing_matrix(candidates[i], y);
      double min_eig;
      if (L.rows() == 1) {
        min_eig = L(0, 0);
      } else {
        Eigen::LLT<Eigen::MatrixXd> llt(L);
        if (llt.info() == Eigen::Success) continue;  // positive definite: satisfied
        min_eig = Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(L, Eigen::EigenvaluesOnly).eigenvalues()(0);
      }
      const double rel = -min_eig / std::max(1.0, L.cwiseAbs().maxCoeff());
      worst = std::max(worst, rel);
      if (rel > options.violation_tolerance) violated.push_back({rel, i});
    }
    result.max_violation = worst;
    if (on_round) on_round(result.working_set);
    if (violated.empty()) {
      result.tight = true;
      result.message = fmt::format("tight: {} rounds, {} of {} data constraints in the LMI, none of the others violated",
                                   round, working.size(), candidates.size());
      verify_bound(problem, relaxation, sdp, *used);
      return result;
    }
    if (round == options.max_rounds) {
      result.message = fmt::format("round limit reached: the bound is valid but may be looser than the full "
                                   "relaxation's (max relative violation {:.2e})",
                                   result.max_violation);
      verify_bound(problem, relaxation, sdp, *used);
      return result;
    }
    last_solved = SolvedRound{problem, std::make_unique<MomentRelaxation>(std::move(relaxation)), sdp, used,
                              result.working_set, result.max_violation};
    std::sort(violated.rbegin(), violated.rend());
    for (int k = 0; k < std::min<int>(options.add_per_round, violated.size()); ++k) working.insert(violated[k].second);
  }
  return result;
}

sdp::VariableBounds MomentVariableBounds(const PolyProblem& problem, const MomentRelaxation& relaxation) {
  const int n = problem.num_vars;
  const int m = relaxation.lmi().num_vars();
  const double inf = std::numeric_limits<double>::infinity();
  sdp::VariableBounds out = sdp::VariableBounds::Uniform(m, -inf, inf);
  // Premise: 1 - x_i^2 >= 0 (up to a positive factor) for every variable i.
  std::vector<char> boxed(n, 0);
  auto check = [&](const Polynomial& g) {
    if (g.terms().size() != 2) return;
    const double a = g.constant_term();
    if (!(a > 0)) return;
    for (int i = 0; i < n; ++i) {
      Exponents e(n, 0);
      e[i] = 2;
      if (g.coefficient(e) == -a) boxed[i] = 1;
    }
  };
  for (const auto& g : problem.inequalities) check(g);
  if (!problem.box.empty())
    for (int i = 0; i < n; ++i)
      if (problem.box[i].first == -1.0 && problem.box[i].second == 1.0) boxed[i] = 1;
  if (std::find(boxed.begin(), boxed.end(), 0) != boxed.end()) return out;
  // LMI variable z_f is bounded when some moment equals it exactly: y_k = 0 + 1 * z_f (checked on the map
  // itself, through moments(): unit vectors give the columns of y = base + T z exactly).
  const std::vector<double> base = relaxation.moments(std::vector<double>(m, 0.0));
  std::vector<int> single(base.size(), -1);  // -1 unseen, >= 0 the one variable, -2 several or not 1.0
  std::vector<double> z(m, 0.0);
  for (int f = 0; f < m; ++f) {
    z[f] = 1.0;
    const auto y = relaxation.moments(z);
    z[f] = 0.0;
    for (std::size_t k = 1; k < y.size(); ++k) {
      if (y[k] == base[k]) continue;
      single[k] = (single[k] == -1 && base[k] == 0.0 && y[k] == 1.0) ? f : -2;
    }
  }
  for (std::size_t k = 1; k < single.size(); ++k)
    if (single[k] >= 0) {
      out.lower[single[k]] = -1.0;
      out.upper[single[k]] = 1.0;
    }
  return out;
}

namespace {

// The LP of ScreenWithLinearProgram / LinearProgramBound: every monomial of degree <= D a free variable y with
// |y| <= 1 and y >= 0 for even monomials; one row per constraint.
struct MomentLp {
  sdp::LmiProblem lp;
  MonomialBasis basis;
};

MomentLp BuildMomentLp(const std::vector<Polynomial>& constraints, int num_vars) {
  int D = 1;
  for (const auto& g : constraints) D = std::max(D, g.degree());
  MomentLp out{sdp::LmiProblem{}, MonomialBasis(num_vars, D)};
  const MonomialBasis& basis = out.basis;
  const int m = static_cast<int>(basis.size()) - 1;
  std::vector<int> even;
  for (int i = 1; i <= m; ++i) {
    bool all_even = true;
    for (auto e : basis[i]) all_even = all_even && e % 2 == 0;
    if (all_even) even.push_back(i);
  }
  const int rows = static_cast<int>(constraints.size()) + 2 * m + static_cast<int>(even.size());
  sdp::LmiProblem& lp = out.lp;
  lp.blocks.push_back({sdp::BlockSpec::Kind::kDiagonal, rows});
  lp.c.assign(m, 0.0);  // feasibility problem unless the caller sets an objective
  lp.F.assign(m + 1, {});
  int r = 0;
  for (const auto& g : constraints) {
    for (const auto& [e, coef] : g.terms()) {
      const long k = basis.index_of(e);
      if (k == 0)
        lp.F[0].push_back({0, r, r, -coef});
      else
        lp.F[k].push_back({0, r, r, coef});
    }
    ++r;
  }
  for (int k = 1; k <= m; ++k) {  // 1 - y >= 0 and 1 + y >= 0
    lp.F[0].push_back({0, r, r, -1.0});
    lp.F[k].push_back({0, r, r, -1.0});
    ++r;
    lp.F[0].push_back({0, r, r, -1.0});
    lp.F[k].push_back({0, r, r, 1.0});
    ++r;
  }
  for (int k : even) {
    lp.F[k].push_back({0, r, r, 1.0});
    ++r;
  }
  return out;
}

// Keeps an infeasibility claim of the LP only with a verified certificate (|y| <= 1 is part of the LP).
void CertifyLpInfeasibility(const sdp::LmiProblem& lp, sdp::SdpSummary& s, sdp::VerifiedBound* certificate) {
  if (s.status != sdp::SdpStatus::kInfeasible) return;
  *certificate = sdp::VerifyInfeasibility(lp, s.X, sdp::VariableBounds::Uniform(lp.num_vars(), -1.0, 1.0));
  if (!certificate->verified()) {
    s.status = sdp::SdpStatus::kNumericalTrouble;
    s.message += "; " + certificate->message;
  }
}

}  // namespace

sdp::SdpSummary ScreenWithLinearProgram(const std::vector<Polynomial>& constraints, int num_vars,
                                        const sdp::SdpOptions& options, sdp::SdpSolver& solver,
                                        sdp::VerifiedBound* certificate) {
  const MomentLp built = BuildMomentLp(constraints, num_vars);
  if (!certificate) return solver.Solve(options, built.lp);
  sdp::SdpOptions keep = options;
  keep.keep_dual_matrix = true;
  auto s = solver.Solve(keep, built.lp);
  CertifyLpInfeasibility(built.lp, s, certificate);
  if (!options.keep_dual_matrix) {
    s.X.clear();
    s.Z.clear();
  }
  return s;
}

LinearProgramBoundResult LinearProgramBound(const std::vector<Polynomial>& constraints, int num_vars, int variable,
                                            int direction, const sdp::SdpOptions& options, sdp::SdpSolver& solver) {
  LinearProgramBoundResult out;
  MomentLp built = BuildMomentLp(constraints, num_vars);
  Exponents e(num_vars, 0);
  e[variable] = 1;
  const long k = built.basis.index_of(e);
  // The LP minimises: min x_k, or min -x_k for the maximum.
  built.lp.c[k - 1] = direction < 0 ? 1.0 : -1.0;
  sdp::SdpOptions keep = options;
  keep.keep_dual_matrix = true;
  auto s = solver.Solve(keep, built.lp);
  out.summary_message = s.message;
  if (s.status == sdp::SdpStatus::kInfeasible) {
    sdp::VerifiedBound cert;
    CertifyLpInfeasibility(built.lp, s, &cert);
    out.status = s.status == sdp::SdpStatus::kInfeasible ? LinearProgramBoundResult::kEmpty
                                                          : LinearProgramBoundResult::kFailed;
    return out;
  }
  if (s.status != sdp::SdpStatus::kOptimal && s.status != sdp::SdpStatus::kInaccurate &&
      s.status != sdp::SdpStatus::kIterationLimit) {
    out.status = LinearProgramBoundResult::kFailed;
    return out;
  }
  // Any multiplier X gives a rigorous bound (weak duality with |y| <= 1), optimal or not: verify it, and use
  // the box edge when the verified value is not finite.
  const auto v = sdp::VerifyLowerBound(built.lp, s.X, sdp::VariableBounds::Uniform(built.lp.num_vars(), -1.0, 1.0),
                                       s.lower_bound);
  if (!v.verified() || !std::isfinite(v.bound)) {
    out.status = LinearProgramBoundResult::kFailed;
    out.summary_message += "; " + v.message;
    return out;
  }
  out.status = LinearProgramBoundResult::kBounded;
  out.bound = std::clamp(direction < 0 ? v.bound : -v.bound, -1.0, 1.0);
  return out;
}

}  // namespace hw::relax
