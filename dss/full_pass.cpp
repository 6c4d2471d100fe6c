#include "dss/full_pass.hpp"

#include <cmath>
#include <set>

#include <fmt/format.h>

namespace hw::dss {

void RunFullPass(const FullPassOptions& options, EngineContext& ctx, PipelineState& state) {
  const std::vector<Objective>& objectives = state.objectives;
  const std::vector<int>& wanted_objectives = state.wanted_objectives;
  const PassOutcomes& cheap = state.cheap;
  const PassOutcomes& settled = state.settled;
  const std::map<int, double>& witnessed = state.witnessed;
  std::vector<OrthantWork>& orthants = state.orthants;
  PassOutcomes full;
  std::vector<double> current(objectives.size(), NAN);  // aggregated endpoint of the finished full-order jobs
  std::map<int, std::set<int>> active_rows;              // per orthant: data rows active at full order so far
  for (const auto& [key, r] : settled) {
    full[key] = r;
    const int o = key.second, dir = objectives[o].dir;
    if (r.status == JobStatus::kSolved && (std::isnan(current[o]) || (dir < 0 ? r.bound < current[o] : r.bound > current[o])))
      current[o] = r.bound;
  }
  int total = 0;
  for (int o : wanted_objectives)
    for (const auto& w : orthants)
      if (!w.empty() && !settled.count({w.index, o})) ++total;
  ctx.progress.Phase(fmt::format("order {} relaxations", options.order), total);
  while (true) {
    std::vector<RelaxJob> wave;
    std::vector<int> wave_objective;
    for (int o : wanted_objectives) {
      const int dir = objectives[o].dir;
      const OrthantWork* best = nullptr;
      double best_val = 0.0;
      for (const auto& w : orthants) {
        if (w.empty() || full.count({w.index, o})) continue;
        const auto& c = cheap.at({w.index, o});
        // A failed cheap job cannot be used to skip: it must be solved. A skipped one carries a valid bound (the
        // box edge, or the orthant's sign bound beyond a witnessed value).
        const double v = c.status == JobStatus::kSolved || c.status == JobStatus::kSkipped ? c.bound : (dir < 0 ? -INFINITY : INFINITY);
        // The endpoint is at least as extreme as the finished jobs' bounds and as a witnessed value.
        const double witness = StopBeyond(witnessed, o);
        const bool can_move = (std::isnan(current[o]) || (dir < 0 ? v < current[o] : v > current[o])) &&
                              (std::isnan(witness) || (dir < 0 ? v < witness : v > witness));
        if (!can_move) continue;
        if (!best || (dir < 0 ? v < best_val : v > best_val)) {
          best = &w;
          best_val = v;
        }
      }
      if (!best) continue;
      std::set<int> rows(active_rows[best->index]);
      for (int r : RowsOfWorkingSet(*best, cheap.at({best->index, o}).working_set)) rows.insert(r);
      wave.push_back({best, objectives[o], options.order, PositionsOfRows(*best, {rows.begin(), rows.end()}), 0,
                      StopBeyond(witnessed, o)});
      wave_objective.push_back(o);
    }
    if (wave.empty()) break;
    const auto outs = RunRelaxationJobs(ctx, wave, orthants);
    for (std::size_t i = 0; i < wave.size(); ++i) {
      const int l = wave[i].orthant->index, o = wave_objective[i];
      full[{l, o}] = outs[i];
      // A job that stopped at a witnessed value has not converged: its blocks are no warm start for later waves.
      if (!outs[i].beyond_known_value)
        for (int r : RowsOfWorkingSet(*wave[i].orthant, outs[i].working_set)) active_rows[l].insert(r);
      if (outs[i].status == JobStatus::kSolved) {
        const int dir = objectives[o].dir;
        if (std::isnan(current[o]) || (dir < 0 ? outs[i].bound < current[o] : outs[i].bound > current[o]))
          current[o] = outs[i].bound;
      }
    }
  }
  for (const auto& w : orthants)
    for (int o : wanted_objectives)
      if (!full.count({w.index, o}) && !w.empty()) {
        auto c = cheap.at({w.index, o});
        c.message = fmt::format("skipped at order {}: its order-{} bound cannot move the interval", options.order,
                                options.cheap_order);
        if (c.status == JobStatus::kSolved) c.status = JobStatus::kSkipped;
        full[{w.index, o}] = c;
      }
  state.full = std::move(full);
}

}  // namespace hw::dss
