#include "pop/constraint_generation.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <optional>
#include <set>
#include <utility>

#include <fmt/format.h>

namespace hw::pop {

bool ValidBlockOrderCap(int cap, std::string* error) {
  if (cap >= -1) return true;
  if (error)
    *error = fmt::format("row block order {} is invalid; give -1 (full order) or a localizing order >= 0 (1 at order "
                         "3: 9x9 blocks)", cap);
  return false;
}

bool ConstraintGenerationOptions::IsValid(std::string* error) const {
  auto fail = [&](std::string m) {
    if (error) *error = std::move(m);
    return false;
  };
  if (order < 0) return fail("order must be >= 0");
  if (max_rounds < 1) return fail("max_rounds must be >= 1");
  if (add_per_round < 1) return fail("add_per_round must be >= 1");
  if (!ValidBlockOrderCap(block_order_cap, error)) return false;
  if (!(violation_tolerance > 0)) return fail("violation_tolerance must be > 0");
  if (!(active_fraction >= 0 && active_fraction < 1)) return fail("active_fraction must be in [0, 1)");
  if (!verify.IsValid(error)) return false;
  return sdp.IsValid(error);
}

std::string ToString(BoundOrigin o) {
  switch (o) {
    case BoundOrigin::kNone: return "none";
    case BoundOrigin::kFinalRound: return "final round";
    case BoundOrigin::kEarlierRound: return "earlier round";
  }
  return "unknown";
}

namespace {

// The LMI of one round: core inequalities and block candidates at full order, the other candidates (when
// linear_rows_first) as scalar moment constraints.
struct RoundRelaxation {
  PolyProblem problem;
  std::unique_ptr<MomentRelaxation> relaxation;
  int linear_rows = 0;
};

RoundRelaxation BuildRound(const PolyProblem& core, const std::vector<Polynomial>& candidates,
                           const std::set<int>& blocks, bool linear_rows_first, int order, int block_order_cap) {
  RoundRelaxation r;
  r.problem = core;
  std::vector<int> orders(core.inequalities.size(), -1);
  for (int i : blocks) {
    r.problem.inequalities.push_back(candidates[i]);
    orders.push_back(block_order_cap);
  }
  if (linear_rows_first)
    for (int i = 0; i < static_cast<int>(candidates.size()); ++i)
      if (!blocks.count(i)) {
        r.problem.inequalities.push_back(candidates[i]);
        orders.push_back(0);
        ++r.linear_rows;
      }
  r.relaxation = std::make_unique<MomentRelaxation>(r.problem, order, orders);
  return r;
}

// Omitted blocks violated at moments y: (relative violation, candidate), and the largest violation.
std::pair<std::vector<std::pair<double, int>>, double> ViolatedBlocks(const MomentRelaxation& relaxation,
                                                                     const std::vector<Polynomial>& candidates,
                                                                     const std::set<int>& blocks,
                                                                     const std::vector<double>& y, double tolerance,
                                                                     int block_order_cap) {
  std::vector<std::pair<double, int>> violated;
  double worst = 0.0;
  for (int i = 0; i < static_cast<int>(candidates.size()); ++i) {
    if (blocks.count(i)) continue;
    const Eigen::MatrixXd L = relaxation.localizing_matrix(candidates[i], y, block_order_cap);
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
    if (rel > tolerance) violated.push_back({rel, i});
  }
  std::sort(violated.rbegin(), violated.rend());
  return {violated, worst};
}

// Candidates of `blocks` whose multiplier block (X) has a trace above `fraction` times the largest among them.
// The round's problem lists core inequalities first, then the block candidates in `blocks` order.
std::vector<int> ActiveBlocks(const MomentRelaxation& relaxation, const std::vector<Eigen::MatrixXd>& X,
                              std::size_t num_core, const std::set<int>& blocks, double fraction) {
  std::vector<std::pair<int, double>> traces;
  const auto& block_of = relaxation.block_of_inequality();
  std::size_t i = num_core;
  for (int candidate : blocks) {
    const int b = i < block_of.size() ? block_of[i] : -1;
    ++i;
    if (b >= 0 && b < static_cast<int>(X.size())) traces.push_back({candidate, X[b].trace()});
  }
  double largest = 0.0;
  for (const auto& [c, t] : traces) largest = std::max(largest, t);
  std::vector<int> active;
  for (const auto& [c, t] : traces)
    if (t > fraction * largest) active.push_back(c);
  return active;
}

}  // namespace

ConstraintGenerationResult SolveWithConstraintGeneration(const ConstraintGenerationOptions& options,
                                                         const PolyProblem& core,
                                                         const std::vector<Polynomial>& candidates,
                                                         std::vector<int> initial, sdp::SdpSolver& solver,
                                                         const std::function<void(const GenerationRound&)>& on_round,
                                                         sdp::SdpSolver* fallback) {
  ConstraintGenerationResult result;
  std::string error;
  if (!options.IsValid(&error) || !core.IsValid(&error)) {
    result.message = error;
    return result;
  }
  std::set<int> blocks(initial.begin(), initial.end());
  int order = options.order;
  {
    PolyProblem all = core;
    for (const auto& g : candidates) all.inequalities.push_back(g);
    order = std::max(order == 0 ? all.minimal_order() : order, all.minimal_order());
  }
  const bool verify = options.verify.enabled;
  sdp::SdpOptions sdp_options = options.sdp;
  if (verify) sdp_options.keep_dual_matrix = true;

  // The best valid bound over all rounds (each round relaxes a subset of the inequalities, so each is valid for
  // the full set). With verification on, a round's bound is the verified bound of its multiplier, whether the
  // solve converged or not; with verification off only converged rounds count (their floating-point bound).
  struct BestBound {
    bool any = false;
    double value = 0.0, float_value = 0.0, primal = 0.0;  // in the problem's own sign convention
    int round = 0;
    bool unfinished = false;
    sdp::VerifiedBound verification;
  } best;
  auto offer = [&](int round, const sdp::SdpSummary& sdp, const sdp::VerifiedBound* v, double sign) {
    double value;
    if (verify) {
      if (!v || !v->verified() || !std::isfinite(v->bound)) return;
      value = sign * v->bound;
    } else {
      if (sdp.status != sdp::SdpStatus::kOptimal) return;
      value = sign * sdp.lower_bound;
    }
    const bool better = !best.any || (sign > 0 ? value > best.value : value < best.value);
    if (!better) return;
    best.any = true;
    best.value = value;
    best.float_value = sign * sdp.lower_bound;
    best.primal = sign * sdp.primal_value;
    best.round = round;
    best.unfinished = sdp.status != sdp::SdpStatus::kOptimal;
    if (v) best.verification = *v;
  };
  // Ends the job with the best bound found (or as failed when there is none).
  auto finish = [&](bool converged_final_round, const std::string& why) {
    if (!best.any) {
      result.status = RelaxationStatus::kSolverFailed;
      result.message = why;
      return result;
    }
    result.status = RelaxationStatus::kSolved;
    result.bound = best.value;
    result.float_bound = best.float_value;
    result.primal_value = best.primal;
    result.verification = best.verification;
    result.bound_round = best.round;
    result.bound_from_unfinished_solve = best.unfinished;
    result.origin = best.round == result.rounds ? BoundOrigin::kFinalRound : BoundOrigin::kEarlierRound;
    result.tight = converged_final_round;
    result.message = why;
    if (result.origin == BoundOrigin::kEarlierRound)
      result.message += fmt::format("; the bound of round {} is reported (valid: it relaxes a subset of the "
                                    "inequalities)", best.round);
    if (best.unfinished) result.message += "; from the verified last iterate of a solve that stopped short";
    return result;
  };

  std::vector<double> warm_y;
  std::set<int> pruned_once;  // blocks returned to scalar rows once; they are kept if they come back
  int failed_in_a_row = 0;
  for (int round = 1; round <= options.max_rounds; ++round) {
    result.rounds = round;
    GenerationRound report;
    report.round = round;
    RoundRelaxation built =
        BuildRound(core, candidates, blocks, options.linear_rows_first, order, options.block_order_cap);
    const MomentRelaxation& relaxation = *built.relaxation;
    report.blocks = static_cast<int>(blocks.size());
    report.linear_rows = built.linear_rows;
    result.num_moments = relaxation.lmi().c.size();
    result.num_blocks = relaxation.lmi().blocks.size();
    sdp::SdpOptions round_options = sdp_options;
    if (options.warm_start && warm_y.size() == relaxation.lmi().c.size()) round_options.initial_y = warm_y;
    auto sdp = solver.Solve(round_options, relaxation.lmi());
    sdp::SdpSolver* used = &solver;
    if (fallback && options.retry_undecided_rounds && !sdp.decided()) {
      const std::string first = sdp.message;
      result.solve_seconds += sdp.setup_seconds + sdp.solve_seconds;
      auto second = fallback->Solve(sdp_options, relaxation.lmi());
      second.message += " [after " + first + "]";
      // Keep the first attempt's iterate too: both multipliers are verified below when the second also fails.
      if (second.decided() || second.X.size() == relaxation.lmi().blocks.size()) {
        sdp = std::move(second);
        used = fallback;
      }
    }
    result.solve_seconds += sdp.setup_seconds + sdp.solve_seconds;
    result.sdp_iterations += sdp.iterations;
    report.seconds = sdp.setup_seconds + sdp.solve_seconds;
    report.status = sdp::ToString(sdp.status);
    result.working_set.assign(blocks.begin(), blocks.end());
    result.last_sdp = sdp;
    const double sign = relaxation.objective_sign();
    const auto bounds = MomentVariableBounds(built.problem, relaxation);
    auto announce = [&](int violated) {
      report.violated = violated;
      report.bound = best.any ? best.value : NAN;
      report.bound_verified = verify && best.any;
      result.history.push_back(report);
      if (on_round) on_round(report);
    };

    if (sdp.status == sdp::SdpStatus::kInfeasible) {
      // An emptiness claim stands only on a verified certificate; the other backend gets one chance to give one.
      sdp::VerifiedBound cert;
      if (verify) {
        cert = sdp::VerifyInfeasibility(relaxation.lmi(), sdp.X, bounds);
        if (!cert.verified() && fallback && used != fallback) {
          auto second = fallback->Solve(sdp_options, relaxation.lmi());
          result.solve_seconds += second.setup_seconds + second.solve_seconds;
          if (second.status == sdp::SdpStatus::kInfeasible) {
            auto v = sdp::VerifyInfeasibility(relaxation.lmi(), second.X, bounds);
            v.seconds += cert.seconds;
            cert = v;
          }
        }
      }
      announce(-1);
      if (!verify || cert.verified()) {
        result.status = RelaxationStatus::kInfeasible;
        result.verification = cert;
        result.message = fmt::format("relaxation with {} of {} data constraints as blocks is infeasible: the set is "
                                     "empty", blocks.size(), candidates.size());
        return result;
      }
      return finish(false, fmt::format("relaxation reported infeasible, but {}: the set is NOT declared empty",
                                       cert.message));
    }
    if (sdp.status == sdp::SdpStatus::kUnbounded) {
      announce(-1);
      result.status = RelaxationStatus::kUnbounded;
      result.message = "relaxation unbounded: add a box";
      return result;
    }

    // Every round's multiplier gives a rigorous bound, converged or not.
    if (verify && sdp.X.size() == relaxation.lmi().blocks.size()) {
      auto v = sdp::VerifyMultiplier(relaxation.lmi(), sdp.X, bounds, sdp.lower_bound,
                                     options.verify.acceptable_correction);
      offer(round, sdp, &v, sign);
    } else {
      offer(round, sdp, nullptr, sign);
    }
    if (best.any && !std::isnan(options.stop_beyond) &&
        (core.maximize ? best.value <= options.stop_beyond : best.value >= options.stop_beyond)) {
      announce(-1);
      result.beyond_known_value = true;
      return finish(false, fmt::format("round {}: the bound is already beyond a value attained elsewhere, so more "
                                       "rounds cannot move the extreme", round));
    }
    const bool solved = sdp.status == sdp::SdpStatus::kOptimal;
    // A round that stops short still points at violated blocks (its last iterate); after two such rounds in a
    // row, or without an iterate, the job ends with the best verified bound so far.
    failed_in_a_row = solved ? 0 : failed_in_a_row + 1;
    const std::string stop_reason =
        fmt::format("round {}: {}: {} ({})", round, sdp.solver, sdp::ToString(sdp.status), sdp.message);
    if (!solved && (failed_in_a_row >= 2 || sdp.y.size() != relaxation.lmi().c.size() || round == options.max_rounds)) {
      announce(-1);
      return finish(false, stop_reason);
    }
    if (solved) {
      warm_y = sdp.y;
      result.last_y = sdp.y;
      if (sdp.X.size() == relaxation.lmi().blocks.size()) {
        result.active_set = ActiveBlocks(relaxation, sdp.X, core.inequalities.size(), blocks, options.active_fraction);
        report.active = static_cast<int>(result.active_set.size());
      }
    }
    const auto y = relaxation.moments(sdp.y);
    if (solved) result.first_moments.assign(y.begin() + 1, y.begin() + 1 + core.num_vars);
    const auto [violated, worst] =
        ViolatedBlocks(relaxation, candidates, blocks, y, options.violation_tolerance, options.block_order_cap);
    result.max_violation = worst;
    if (!solved && violated.empty()) {  // nothing to add, and the moments of an unfinished solve prove nothing
      announce(0);
      return finish(false, stop_reason);
    }
    const bool converged = solved && violated.empty();
    if (solved && (converged || round == options.max_rounds)) {
      // The bound that is reported: verify the final round with re-solves when the plain check was loose.
      if (verify) {
        auto v = sdp::VerifyOptimalSolve(options.verify, sdp_options, relaxation.lmi(), bounds, sdp, *used);
        offer(round, sdp, &v, sign);
      }
      announce(static_cast<int>(violated.size()));
      if (converged)
        return finish(true, fmt::format("tight: {} rounds, {} of {} data constraints as blocks, none of the others "
                                        "violated", round, blocks.size(), candidates.size()));
      return finish(false, fmt::format("round limit reached: the bound is valid but may be looser than the full "
                                       "relaxation's (max relative violation {:.2e})", worst));
    }
    announce(static_cast<int>(violated.size()));
    if (options.prune_inactive && solved && !result.active_set.empty()) {
      const std::set<int> active(result.active_set.begin(), result.active_set.end());
      for (auto it = blocks.begin(); it != blocks.end();) {
        if (!active.count(*it) && !pruned_once.count(*it)) {
          pruned_once.insert(*it);
          it = blocks.erase(it);
        } else {
          ++it;
        }
      }
    }
    for (int k = 0; k < std::min<int>(options.add_per_round, violated.size()); ++k) blocks.insert(violated[k].second);
  }
  return result;
}

sdp::VariableBounds MomentVariableBounds(const PolyProblem& problem, const MomentRelaxation& relaxation) {
  const int n = problem.num_vars;
  const int m = relaxation.lmi().num_vars();
  const double inf = std::numeric_limits<double>::infinity();
  sdp::VariableBounds out = sdp::VariableBounds::Uniform(m, -inf, inf);
  // A radius R_i with x_i^2 <= R_i^2 implied by an inequality the relaxation localizes:
  //   a - sum_j b_j x_j^2 >= 0 (a, b_j > 0; one variable or a ball): R_i^2 = a / b_i, since the localizer's
  //   diagonal gives sum_j b_j y_{2beta + 2e_j} <= a y_{2beta} and even moments are >= 0;
  //   (x_i - lo)(hi - x_i) >= 0 (a box): y_{2beta+2e_i} <= |lo + hi| |y_{2beta+e_i}| + |lo hi| y_{2beta} and the
  //   2x2 minor |y_{2beta+e_i}| <= sqrt(y_{2beta} y_{2beta+2e_i}) give R_i = (c + sqrt(c^2 + 4 |lo hi|)) / 2,
  //   c = |lo + hi|.
  // Then |y_alpha| <= prod R_i^alpha_i for every moment of the relaxation (even moments by the chain down to
  // y_0 = 1, the others by 2x2 minors of the moment matrix).
  std::vector<double> radius(n, inf);
  auto take = [&](int i, double r) { radius[i] = std::min(radius[i], r); };
  // Only inequalities with their full localizing matrix count: the chain needs its diagonal up to x^(2 beta),
  // |beta| = delta - 1 (a scalar row L_y(g) >= 0 bounds the second moments alone).
  const auto& block_of = relaxation.block_of_inequality();
  const int full_size = static_cast<int>(MonomialBasis::count(n, relaxation.order() - 1));
  for (std::size_t gi = 0; gi < problem.inequalities.size(); ++gi) {
    const Polynomial& g = problem.inequalities[gi];
    const double a = g.constant_term();
    if (!(a > 0) || g.degree() != 2) continue;
    const int localized = gi >= block_of.size() ? -1 : block_of[gi] < 0 ? 1 : relaxation.lmi().blocks[block_of[gi]].size;
    if (localized < full_size) continue;  // a scalar row (size 1) suffices at order 1 only
    std::vector<double> b(n, 0.0);
    bool shape = true;
    for (const auto& [e, c] : g.terms()) {
      if (degree_of(e) == 0) continue;
      int var = -1;
      for (int i = 0; i < n; ++i)
        if (e[i] == 2) var = i;
      if (var < 0 || degree_of(e) != 2 || !(c < 0)) {
        shape = false;
        break;
      }
      b[var] = -c;
    }
    if (!shape) continue;
    for (int i = 0; i < n; ++i)
      if (b[i] > 0) take(i, std::sqrt(a / b[i]));
  }
  for (int i = 0; i < static_cast<int>(problem.box.size()) && i < n; ++i) {
    const auto [lo, hi] = problem.box[i];
    const double c = std::abs(lo + hi);
    take(i, 0.5 * (c + std::sqrt(c * c + 4 * std::abs(lo * hi))));
  }
  for (double r : radius)
    if (!std::isfinite(r)) return out;
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
  const auto& monomials = relaxation.index().basis();
  for (std::size_t k = 1; k < single.size(); ++k)
    if (single[k] >= 0) {
      double bound = 1.0;
      const Exponents& e = monomials[k];
      for (int i = 0; i < n; ++i) bound *= std::pow(radius[i], e[i]);
      // Rounding of the product (radii other than 1): one ulp per factor is far below this allowance.
      if (bound != 1.0) bound *= 1.0 + 1e-12;
      out.lower[single[k]] = -bound;
      out.upper[single[k]] = bound;
    }
  return out;
}

}  // namespace hw::pop
