#include "dss/cheap_pass.hpp"

#include <algorithm>
#include <cmath>
#include <set>

#include <fmt/format.h>

#include "dss/box_contraction.hpp"
#include "dss/edge_witness.hpp"
#include "dss/row_reduction.hpp"

namespace hw::dss {
namespace {

// One pass: seeds first, then the other objectives from the seeds' blocks. `seed_rows` (data-row indices per
// orthant) are the blocks the seeds start from. Seeds always run to convergence (no stop at a witnessed value):
// the other objectives start from their blocks, so the stops change no job's path but their own.
PassOutcomes RunOnePass(EngineContext& ctx, const std::vector<Objective>& objectives, const PassOutcomes& settled,
                        const std::map<int, double>& witnessed, std::vector<OrthantWork>& orthants, int order,
                        int max_rounds, const std::string& phase, const std::map<int, std::vector<int>>& seed_rows) {
  PassOutcomes out;
  const int num_objectives = static_cast<int>(objectives.size());
  auto is_settled = [&](int l, int j) { return settled.count({l, j}) > 0; };
  int total = 0;
  for (const auto& o : orthants)
    if (!o.empty())
      for (int j = 0; j < num_objectives; ++j) total += is_settled(o.index, j) ? 0 : 1;
  ctx.progress.Phase(phase, total);
  std::vector<RelaxJob> seeds;
  std::vector<int> seed_objective;
  for (const auto& o : orthants) {
    if (o.empty()) continue;
    int first = 0;
    while (first < num_objectives && is_settled(o.index, first)) ++first;
    if (first == num_objectives) continue;
    const auto it = seed_rows.find(o.index);
    seeds.push_back({&o, objectives[first], order,
                     it == seed_rows.end() ? std::vector<int>{} : PositionsOfRows(o, it->second), max_rounds});
    seed_objective.push_back(first);
  }
  const auto seed_out = RunRelaxationJobs(ctx, seeds, orthants);
  std::vector<RelaxJob> rest;
  std::vector<int> rest_objective;
  for (std::size_t k = 0; k < seeds.size(); ++k) {
    out[{seeds[k].orthant->index, seed_objective[k]}] = seed_out[k];
    for (int j = seed_objective[k] + 1; j < num_objectives; ++j) {
      if (is_settled(seeds[k].orthant->index, j)) continue;
      // The seed's active blocks: its working set less the blocks whose multipliers vanish (they only slow the
      // solves; an objective that needs them gets them back as violated blocks).
      const auto& start = seed_out[k].active_set.empty() ? seed_out[k].working_set : seed_out[k].active_set;
      // Not the seeds: a seed settled here would change the other objectives' starting blocks.
      if (auto by_sign = SettleBySignBeyondWitness(ctx.set, *seeds[k].orthant, objectives[j], StopBeyond(witnessed, j))) {
        out[{seeds[k].orthant->index, j}] = *by_sign;
        ++ctx.counters.jobs_settled_by_sign;
        ctx.progress.Done();
        continue;
      }
      rest.push_back({seeds[k].orthant, objectives[j], order, start, max_rounds, StopBeyond(witnessed, j)});
      rest_objective.push_back(j);
    }
  }
  const auto rest_out = RunRelaxationJobs(ctx, rest, orthants);
  for (std::size_t k = 0; k < rest.size(); ++k) out[{rest[k].orthant->index, rest_objective[k]}] = rest_out[k];
  for (const auto& [key, r] : settled) out[key] = r;
  return out;
}

}  // namespace

std::vector<int> PositionsOfRows(const OrthantWork& orthant, const std::vector<int>& data_rows) {
  std::vector<int> pos;
  for (int r : data_rows) {
    const auto it = std::lower_bound(orthant.rows.begin(), orthant.rows.end(), r);
    if (it != orthant.rows.end() && *it == r) pos.push_back(static_cast<int>(it - orthant.rows.begin()));
  }
  return pos;
}

double StopBeyond(const std::map<int, double>& witnessed, int j) {
  const auto it = witnessed.find(j);
  return it == witnessed.end() ? NAN : it->second;
}

CheapPassResult RunCheapPass(const CheapPassOptions& options, EngineContext& ctx, PipelineState& state) {
  CheapPassResult result;
  const std::vector<Objective>& objectives = state.objectives;
  std::vector<OrthantWork>& orthants = state.orthants;
  std::map<int, std::vector<int>> seed_rows;  // data rows active in the previous pass, per orthant
  for (int pass = 0;; ++pass) {
    const bool contracting = pass < options.contraction_passes;
    const std::string phase = contracting ? fmt::format("order {} box contraction {}", options.order, pass + 1)
                                          : fmt::format("order {} relaxations", options.order);
    const int max_rounds = contracting ? std::min(options.contraction_max_rounds, ctx.settings.generation.max_rounds) : 0;
    // A contraction pass wants every bound as tight as its capped rounds allow, so it runs without stops.
    state.cheap = RunOnePass(ctx, objectives, state.settled, contracting ? std::map<int, double>{} : state.witnessed, orthants,
                                 options.order, max_rounds, phase, seed_rows);
    if (!contracting) break;
    for (const auto& [key, r] : state.cheap) {
      const OrthantWork* o = nullptr;
      for (const auto& w : orthants)
        if (w.index == key.first) o = &w;
      auto rows = RowsOfWorkingSet(*o, r.working_set);
      auto& seed = seed_rows[key.first];
      seed.insert(seed.end(), rows.begin(), rows.end());
    }
    for (auto& [l, rows] : seed_rows) {
      std::sort(rows.begin(), rows.end());
      rows.erase(std::unique(rows.begin(), rows.end()), rows.end());
    }
    const double shrink = ContractOrthantBoxes(ctx, objectives, state.cheap, orthants, options.order);
    result.contraction_passes_run = pass + 1;
    ReduceOrthantRows(ctx, orthants);  // the rows in the new boxes
    // Little movement: skip the remaining contraction passes and run the last (full) cheap pass.
    if (shrink < options.contraction_min_shrink) pass = std::max(pass, options.contraction_passes - 1);
  }
  return result;
}

}  // namespace hw::dss
