#pragma once
// Solving a moment relaxation with many candidate inequalities by constraint generation.
//
// Any subset of inequalities gives a relaxation of a LARGER set, so its bound is still valid (a lower
// bound of the min), only possibly looser. If the subset's optimal moments also satisfy every omitted
// localizing constraint (PSD within tolerance), they are feasible for the full relaxation and the bound
// equals the full relaxation's bound. Otherwise the most violated constraints join the working set and
// the relaxation is solved again. Infeasibility of a subset proves infeasibility of the full set.
#include <cmath>
#include <functional>
#include <string>
#include <vector>

#include "pop/moment_relaxation.hpp"
#include "sdp/verified_bound.hpp"

namespace hw::pop {

struct ConstraintGenerationOptions {
  int order = 0;                    // 0 = minimal
  int max_rounds = 40;
  int add_per_round = 20;           // most violated constraints promoted to a block per round
  // Min eigenvalue below -tol * max(1, ||L||) counts as violated. The thin sets of 31 dB data make the bound
  // sensitive to tiny violations: at 1e-6 a job called tight ended 1.5e-3 below the dense relaxation (N = 100,
  // min a1, docs/setmembership_scale.md); at 1e-8 within 1e-6 at N = 100 but 9e-5 below at N = 300 (min alpha3);
  // at 1e-9 within 8.5e-7 at both sizes, in as many rounds.
  double violation_tolerance = 1e-9;
  // Every candidate without a block enters the LMI as the scalar moment constraint L_y(g) >= 0 (its localizing
  // matrix of order 0): implied by its block, so valid, and cheap (one row of the LP block). A candidate gets
  // its full localizing block when that block is violated at the current moments.
  bool linear_rows_first = true;
  // Mixed orders (the bounded-degree hierarchy's middle ground): a candidate's block is its localizing matrix of
  // order min(full, block_order_cap); -1 = full order. Any cap relaxes the full order-delta relaxation, so the
  // bound stays valid; "tight" then means equal to the capped relaxation over every candidate.
  int block_order_cap = -1;
  // A round the backend leaves undecided (CSDP partial success, SDPA pFEAS) is solved again by the `fallback`
  // backend before its verified last iterate is taken. Off by default: on 300-sample records of the paper's example
  // at 31 dB the retries took about half of the SDP time and tightened nothing; without them the study's runs took
  // 145.9 s instead of 240.7 s on average, with endpoints as tight or tighter (docs/setmembership_scale.md,
  // "Retrying undecided rounds"). The fallback still gets its chance at an emptiness certificate that does not verify.
  bool retry_undecided_rounds = false;
  // Pass the previous round's moments to backends that take an initial point (SdpOptions::initial_y).
  bool warm_start = true;
  double active_fraction = 1e-4;  // see ConstraintGenerationResult::active_set
  // Between rounds, blocks whose multipliers vanish go back to scalar rows (any subset still gives a valid bound,
  // and the final check covers every omitted block). A block is pruned at most once, so rounds cannot cycle.
  // Measured both ways (docs/setmembership_scale.md, "Working sets with and without pruning"): without pruning
  // a job needs fewer rounds but larger LMIs; on 300-sample records of the paper's example the wall time went
  // down on some records (143.3 -> 96.3 s) and up on others (191.7 -> 268.8 s), 9 % more in sum over 6 paired
  // runs of the comparison study, so pruning stays on.
  bool prune_inactive = true;
  // A value the objective is known to attain outside this problem (a certified feasible point of another part of
  // the set, in scaled units): once the best valid bound is at or beyond it (>= for min, <= for max), this
  // problem cannot move the extreme over all parts, and the job ends with that bound (`beyond_known_value`).
  // NaN: no such value, the job runs to convergence.
  double stop_beyond = NAN;
  sdp::SdpOptions sdp;
  // Verification (sdp/verified_bound.hpp): every round's multiplier gives a rigorous bound, the final round's
  // with re-solves when needed; an infeasibility certificate that does not verify never declares the set empty.
  sdp::VerifyOptions verify;
  bool IsValid(std::string* error) const;
};

// A cap of the data rows' localizing order: -1 (full order) or >= 0; otherwise false with the message in *error.
bool ValidBlockOrderCap(int cap, std::string* error);

// What one round did, for progress lines and reports.
struct GenerationRound {
  int round = 0;
  int blocks = 0;           // candidates with their full localizing block in this round's LMI
  int linear_rows = 0;      // candidates as scalar moment constraints
  std::string status;       // the solve's SdpStatus
  double bound = NAN;       // the best valid bound so far (NaN: none yet), same sign convention as the result
  bool bound_verified = false;
  int violated = 0;         // omitted blocks violated at this round's moments (-1: not checked)
  int active = -1;          // blocks whose multiplier is not negligible (-1: no multiplier)
  double seconds = 0.0;
};

// Where a job's bound came from: the converged (or round-limited) final round, or an earlier round whose
// relaxation of a subset is valid for the full set.
enum class BoundOrigin { kNone, kFinalRound, kEarlierRound };
std::string ToString(BoundOrigin o);

struct ConstraintGenerationResult {
  RelaxationStatus status = RelaxationStatus::kInvalid;
  std::string message;
  double bound = 0.0;        // valid bound of the optimum (lower for min, upper for max) when kSolved
                             // (the verified bound when verification.verified(), else the floating-point one)
  double float_bound = 0.0;  // the solver's floating-point bound of the round the bound comes from
  sdp::VerifiedBound verification;  // of the round the bound comes from (lower-bound or infeasibility certificate)
  BoundOrigin origin = BoundOrigin::kNone;
  int bound_round = 0;       // the round whose multiplier gave the bound
  bool bound_from_unfinished_solve = false;  // that round's solve stopped short (pFEAS, iteration limit, ...)
  double primal_value = 0.0;
  bool tight = false;        // true: no omitted block is violated, so bound == full relaxation's bound
  bool beyond_known_value = false;  // ended early: the bound already reached options.stop_beyond
  double max_violation = 0.0;  // largest relative violation among omitted blocks at the last checked round
  int rounds = 0;
  std::vector<int> working_set;  // candidates with a block in the last LMI
  // The part of the working set whose multipliers are not negligible in the last solved round (trace of the
  // block's multiplier above active_fraction times the largest): a warm start for other objectives.
  std::vector<int> active_set;
  std::vector<double> first_moments;
  std::vector<double> last_y;    // the last solved round's LMI variables (a warm start for a next job)
  std::size_t num_moments = 0, num_blocks = 0;
  double solve_seconds = 0.0;  // total SDP time over rounds
  int sdp_iterations = 0;
  sdp::SdpSummary last_sdp;
  std::vector<GenerationRound> history;
};

// `core` inequalities are always in the LMI with full blocks; `candidates` get blocks on demand, starting
// from `initial`. `on_round` (optional) sees each round as it ends (progress lines). When the solver fails on a
// round's LMI (neither optimal nor a certified infeasible/unbounded outcome) and options.retry_undecided_rounds is
// set, `fallback` (optional, e.g. the other backend) solves the same LMI before the round counts as failed; an
// infeasibility certificate that does not verify always gets the fallback's. A failed round ends the job with the
// best verified bound of all its rounds (its own last iterate included).
ConstraintGenerationResult SolveWithConstraintGeneration(
    const ConstraintGenerationOptions& options, const PolyProblem& core, const std::vector<Polynomial>& candidates,
    std::vector<int> initial, sdp::SdpSolver& solver,
    const std::function<void(const GenerationRound&)>& on_round = {}, sdp::SdpSolver* fallback = nullptr);

// A-priori bounds of the LMI variables of a moment relaxation, valid for every feasible point of its LMI.
// When every variable has a radius R_i implied by a localized inequality (a - b x_i^2 >= 0, a ball
// a - sum b_j x_j^2 >= 0, or a box lo <= x_i <= hi), every moment up to degree 2 delta satisfies
// |y_alpha| <= prod R_i^alpha_i (for the scaled box [-1, 1]^n: |y_alpha| <= 1); an LMI variable that equals a
// moment inherits that bound. Everything else is unbounded (+-infinity).
sdp::VariableBounds MomentVariableBounds(const PolyProblem& problem, const MomentRelaxation& relaxation);

}  // namespace hw::pop
