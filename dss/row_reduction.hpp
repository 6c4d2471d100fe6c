#pragma once
// Exact reduction of the data inequalities of one sign orthant (stage 2 of the bound engine).
//
// All data rows of one horizon step share a monomial support, so each row g_i is a coefficient vector and its
// localizing matrix M_k(g_i y) is linear in it. If g_i = sum_j lambda_j g_j + lambda_0 * 1 + sum_f mu_f f with
// lambda, mu >= 0, where the g_j are other kept rows and the f are the always-present constraints (box, signs)
// whose localizing order is at least g_i's (ceil(deg / 2) no larger), then M_k(g_i y) is the same nonnegative
// combination of principal submatrices of blocks already in the relaxation: dropping g_i changes no bound, at
// any order, and none of the LP screen either. One LP per row decides it (GLPK, primal simplex from the previous
// basis: only the right-hand side and one column's bounds change between rows). Rows are tested in index order against the rows
// still kept, so every dropped row is implied by the final kept set (implication is transitive).
//
// Dropping a row only enlarges the relaxed set, so the reduction can never invalidate a bound; the LP's
// accuracy matters for tightness alone, and a combination is accepted only when its residual is checked.
#include <string>
#include <vector>

#include "core/polynomial.hpp"
#include "dss/row_reduction_options.hpp"

namespace hw::dss {

struct RowGroupCount {
  int step = 0;       // horizon step s of the rows
  int rows = 0;       // rows before the reduction
  int kept = 0;       // rows kept
  int iteration_limited = 0;  // rows kept because their LP hit the simplex iteration limit
};

struct RowReductionResult {
  std::vector<int> kept;                // indices into `rows`, ascending
  std::vector<RowGroupCount> per_step;  // ascending step
  int linear_programs = 0;
  int restarts_after_limit = 0;         // LPs that cycled from the warm basis and were solved from the standard one
  double seconds = 0.0;
};

// rows[i] with step[i]: the data inequalities g_i >= 0 of one orthant; fixed: constraints present in every
// relaxation (box and sign constraints), usable in combinations.
RowReductionResult ReduceDataRows(const RowReductionOptions& options, const std::vector<Polynomial>& rows,
                                  const std::vector<int>& step, const std::vector<Polynomial>& fixed);

}  // namespace hw::dss

#include "dss/job_context.hpp"
#include "dss/job_dispatch.hpp"

namespace hw::dss {

// Stage 2 of the bound engine: reduces the data rows of every live orthant in its current box (one job per
// orthant; the kept rows and the counts per step land in each OrthantWork).
void ReduceOrthantRows(EngineContext& ctx, std::vector<OrthantWork>& orthants);

// The reduction's job kind: {"kind": "reduce", "l", "box", ["step"]} -> {"kept", "per_step", "linear_programs",
// "seconds"}; rows never combine across horizon steps, so each step may be a job of its own (no "step": all).
inline constexpr char kReduceJob[] = "reduce";
nlohmann::json AnswerReduceJob(const JobContext& job, const nlohmann::json& spec);

}  // namespace hw::dss
