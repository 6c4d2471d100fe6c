#include "pop/moment_lp.hpp"

#include <algorithm>
#include <cmath>

namespace hw::pop {

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

}  // namespace hw::pop
