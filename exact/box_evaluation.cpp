#include "exact/box_evaluation.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <tuple>

#include <fmt/format.h>

#include "exact/enum_names.hpp"
#include "exact/safe_bound.hpp"

namespace hw::exact {

std::string ToString(GammaRatio ratio) {
  switch (ratio) {
    case GammaRatio::kLargest: return "largest";
    case GammaRatio::kRotate: return "rotate";
    case GammaRatio::kPooled: return "pooled";
  }
  return "largest";
}

bool ParseGammaRatio(const std::string& text, GammaRatio* ratio) {
  return ParseByName(text, {GammaRatio::kLargest, GammaRatio::kRotate, GammaRatio::kPooled}, ratio);
}

namespace {

using Clock = std::chrono::steady_clock;

// How close to its dual bound a bounding LP must come, in the parameter's units: the caller's need when it set
// one (the branch and bound: a share of the gap it stops at), else this fraction of the box's width in the
// parameter. The certified bound loses at most that much.
constexpr double kAcceptableGapOfWidth = 1e-5;
double AcceptableGap(const LpSolveOptions& lp, const Interval& range) {
  return lp.acceptable_gap > 0 ? lp.acceptable_gap : kAcceptableGapOfWidth * (range.hi - range.lo);
}

// Ended with an answer: optimal, or stopped at the objective cutoff.
bool Solved(LpStatus status) { return status == LpStatus::kOptimal || status == LpStatus::kCutoff; }

// The slack LP of a window: a rigorous lower bound of the largest residual, and the solve itself.
struct SlackSolve {
  double lower_bound = -1.0;
  LpResult result;
};

SlackSolve SolveSlack(const LiftedData& data, const ParamBox& box, Window window, const BoxEvaluationOptions& options,
                      LpSolver& solver, const LpBasis& warm) {
  LiftedLp lifted = BuildLiftedLp(data, box, window, LiftedForm::kFeasibility);
  lifted.SetSlackObjective();
  SlackSolve out;
  LpSolveOptions lp = options.lp;
  lp.objective_cutoff = 0.0;  // a positive residual bound is all a pruning test needs
  out.result = solver.Solve(lifted.lp, warm, lp);
  // Any dual vector certifies: even a solve that stopped early may prove the box empty.
  if (!out.result.duals.empty()) out.lower_bound = SafeLowerBound(lifted.lp, out.result.duals);
  return out;
}

std::vector<double> ParameterValues(const LiftedLp& lifted, const std::vector<double>& primal) {
  std::vector<double> p;
  if (primal.size() != static_cast<std::size_t>(lifted.lp.num_cols())) return p;
  for (int col : lifted.param_col) p.push_back(primal[col]);
  return p;
}

// The ratio's terms (index into beta_col, sign of b_j) over the b_j of one sign on the box; empty when none has.
std::vector<std::pair<int, double>> RatioTerms(const LiftedData& data, const ParamBox& box, GammaRatio ratio,
                                               int turn) {
  const auto& lay = data.layout;
  std::vector<std::tuple<double, int, double>> signed_b;  // (-margin, j, sign): farthest first, then by index
  for (int j = 0; lay.b_begin + j < lay.count(); ++j) {
    const Interval b = box[lay.b_begin + j];
    const double margin = b.lo > 0 ? b.lo : (b.hi < 0 ? -b.hi : 0.0);
    if (margin > 0.0) signed_b.emplace_back(-margin, j, b.lo > 0 ? 1.0 : -1.0);
  }
  std::sort(signed_b.begin(), signed_b.end());
  std::vector<std::pair<int, double>> terms;
  for (const auto& [margin, j, sign] : signed_b) terms.emplace_back(j, sign);
  if (terms.empty() || ratio == GammaRatio::kPooled) return terms;
  const std::size_t pick = ratio == GammaRatio::kRotate ? static_cast<std::size_t>(turn) % terms.size() : 0;
  return {terms[pick]};
}

}  // namespace

nlohmann::json PruneCertificate::to_json() const {
  return {{"window", {window.begin, window.end}}, {"residual_lower_bound", residual_lower_bound}};
}

PruneCertificate PruneCertificate::from_json(const nlohmann::json& j) {
  PruneCertificate c;
  c.window = {j.at("window").at(0).get<int>(), j.at("window").at(1).get<int>()};
  c.residual_lower_bound = j.at("residual_lower_bound").get<double>();
  return c;
}

bool BoxEvaluationOptions::IsValid(std::string* error) const {
  if (cheap_window < 0 || cheap_windows < 0) {
    if (error) *error = "cheap windows: length and count must be >= 0";
    return false;
  }
  return lp.IsValid(error);
}

Window WholeRecord(const LiftedData& data) { return {0, data.num_samples}; }

std::vector<Window> CheapWindows(const LiftedData& data, int length, int count) {
  std::vector<Window> windows;
  if (length <= 0 || count <= 0 || 2 * length > data.num_samples) return windows;
  for (int c = 0; c < count; ++c) {
    const int begin = count == 1 ? 0 : static_cast<int>(static_cast<long>(data.num_samples - length) * c / (count - 1));
    windows.push_back({begin, begin + length});
  }
  return windows;
}

BoxEvaluation TestBoxEmpty(const LiftedData& data, const ParamBox& box, const BoxEvaluationOptions& options,
                           LpSolver& solver, const LpBasis& warm) {
  const auto start = Clock::now();
  BoxEvaluation out;
  auto finish = [&]() {
    out.seconds = std::chrono::duration<double>(Clock::now() - start).count();
    return out;
  };
  std::vector<Window> windows = CheapWindows(data, options.cheap_window, options.cheap_windows);
  windows.push_back(WholeRecord(data));
  for (const Window& w : windows) {
    const bool whole = w == WholeRecord(data);
    SlackSolve s = SolveSlack(data, box, w, options, solver, whole ? warm : LpBasis{});
    ++out.lps;
    if (!Solved(s.result.status)) ++out.lp_failures;
    if (s.lower_bound > 0.0) {
      out.verdict = BoxVerdict::kPruned;
      out.certificate = PruneCertificate{w, s.lower_bound};
      return finish();
    }
    if (whole) {
      out.basis = s.result.basis;
      const LiftedLp shape = BuildLiftedLp(data, box, w, LiftedForm::kFeasibility);
      out.point = ParameterValues(shape, s.result.primal);
    }
  }
  return finish();
}

namespace {

// One LP of the bounding form with objective `sign * (obj)`; returns the rigorous lower bound of sign * obj.
struct BoundSolve {
  double lower_bound = -INFINITY;
  LpResult result;
};

// Any dual vector certifies, so a solve that stopped short (iteration limit, stall) still gives a bound, only
// a looser one; an LP found infeasible goes to the emptiness test instead.
BoundSolve SolveBound(LiftedLp& lifted, LpSolver& solver, const LpBasis& warm, const LpSolveOptions& options) {
  BoundSolve out;
  out.result = solver.Solve(lifted.lp, warm, options);
  if (out.result.status != LpStatus::kInfeasible && !out.result.duals.empty())
    out.lower_bound = SafeLowerBound(lifted.lp, out.result.duals);
  return out;
}

// A bound to use: from an optimal solve, or a finite one from a solve that stopped short.
bool Usable(const BoundSolve& s) { return s.result.status == LpStatus::kOptimal || std::isfinite(s.lower_bound); }

}  // namespace

BoxEvaluation BoundObjective(const LiftedData& data, const ParamBox& box, const Objective& objective,
                             const BoxEvaluationOptions& options, LpSolver& solver, const LpBasis& warm,
                             GammaRatio ratio, int turn, std::optional<double> ratio_start) {
  const auto start = Clock::now();
  const auto& lay = data.layout;
  const double sign = objective.maximise ? -1.0 : 1.0;  // every LP minimises sign * objective
  LiftedLp lifted = BuildLiftedLp(data, box, WholeRecord(data), LiftedForm::kBounding);
  BoxEvaluation out;
  auto failed_lp = [&]() {
    // Infeasible (or failed) in floating point: only a certificate may drop the box.
    BoxEvaluation empty = TestBoxEmpty(data, box, options, solver, warm);
    empty.lps += out.lps;
    empty.lp_failures += out.lp_failures;
    empty.seconds = std::chrono::duration<double>(Clock::now() - start).count();
    return empty;
  };
  const bool is_gamma = objective.parameter >= lay.gamma_begin && objective.parameter < lay.gamma_begin + lay.num_gamma;
  const std::vector<std::pair<int, double>> terms =
      is_gamma ? RatioTerms(data, box, ratio, turn) : std::vector<std::pair<int, double>>{};
  if (terms.empty()) {
    std::vector<double> weights(lifted.param_col.size(), 0.0);
    weights[objective.parameter] = sign;
    lifted.SetParameterObjective(weights);
    LpSolveOptions lp = options.lp;
    lp.acceptable_gap = AcceptableGap(options.lp, box[objective.parameter]);
    BoundSolve s = SolveBound(lifted, solver, warm, lp);
    ++out.lps;
    if (s.result.status != LpStatus::kOptimal) ++out.lp_failures;
    if (!Usable(s)) return failed_lp();
    out.bound = sign * s.lower_bound;
    out.lp_value = sign * s.result.objective;
    out.point = ParameterValues(lifted, s.result.primal);
    out.basis = s.result.basis;
  } else {
    // gamma_k = (sum_j s_j beta_jk) / |B| with B = sum_j s_j b_j, s_j the sign of b_j: Dinkelbach steps
    // g <- ratio at the LP's optimum, then the certificate min sign*(sum_j s_j (beta_jk - g b_j)) >= m  =>
    // sign*gamma_k >= sign*g + m / |B| (the |B| end chosen by the sign of m).
    const int k = objective.parameter - lay.gamma_begin + 1;  // beta column index (0 is b_j)
    auto signed_b = [&](const std::pair<int, double>& term) {
      const Interval b = box[lay.b_begin + term.first];
      return term.second > 0 ? b : -b;
    };
    Interval abs_b = signed_b(terms.front());  // |B| over the box, > 0 (one term: exact, no rounding)
    for (std::size_t t = 1; t < terms.size(); ++t) abs_b += signed_b(terms[t]);
    const double b_near = abs_b.lo, b_far = abs_b.hi;
    const Interval& range = box[objective.parameter];
    double g = ratio_start && range.lo <= *ratio_start && *ratio_start <= range.hi ? *ratio_start : range.mid();
    LpBasis basis = warm;
    std::optional<double> best;
    LpSolveOptions lp = options.lp;  // a gap m in the objective moves the gamma bound by m / |b|
    lp.acceptable_gap = AcceptableGap(options.lp, box[objective.parameter]) * b_near;
    for (int step = 0; step < 8; ++step) {
      lifted.SetRatioObjective(terms, k, g);
      for (double& c : lifted.lp.obj) c *= sign;
      BoundSolve s = SolveBound(lifted, solver, basis, lp);
      ++out.lps;
      if (s.result.status != LpStatus::kOptimal) ++out.lp_failures;
      if (!Usable(s)) {
        if (best) break;
        return failed_lp();
      }
      basis = s.result.basis;
      out.basis = s.result.basis;
      out.point = ParameterValues(lifted, s.result.primal);
      // sign * (gamma - g) * |b| >= m over the box  =>  sign * gamma >= sign * g + m / |b|.
      const double m = s.lower_bound;
      // 1/|b| is itself rounded: widen it outward by an ulp on each side.
      const Interval inv = m >= 0 ? Interval(RoundDown(1.0 / b_far), RoundUp(1.0 / b_far))
                                  : Interval(RoundDown(1.0 / b_near), RoundUp(1.0 / b_near));
      const double signed_bound = (Interval(sign * g) + Interval(m) * inv).lo;
      const double candidate = sign * signed_bound;
      if (!best || (objective.maximise ? candidate < *best : candidate > *best)) best = candidate;
      double beta = 0.0, bj = 0.0;
      for (const auto& [j, s_j] : terms) {
        beta += s_j * s.result.primal[lifted.beta_col[j][k]];
        bj += s_j * s.result.primal[lifted.beta_col[j][0]];
      }
      out.lp_value = beta / bj;
      const double g_next = beta / bj;
      // The LP's best ratio lies between the ratio reached (g_next, a point of the relaxation) and the certified
      // bound: once they are within the accuracy asked, more steps cannot tighten the bound by more.
      if (std::isfinite(g_next) && std::abs(candidate - g_next) <= lp.acceptable_gap / b_near) break;
      // Converged once the ratio moves by less than a millionth of the box: a simplex returns the same vertex
      // and stops at once, an interior point's central solution keeps moving by rounding amounts (without this
      // every box would spend all its steps, and the budget with them).
      const double settled = std::max(1e-12 * std::max(1.0, std::abs(g)),
                                      1e-6 * (box[objective.parameter].hi - box[objective.parameter].lo));
      if (!std::isfinite(g_next) || std::abs(g_next - g) <= settled) break;
      g = g_next;
    }
    out.bound = best;
  }
  out.seconds = std::chrono::duration<double>(Clock::now() - start).count();
  return out;
}

}  // namespace hw::exact
