#include "relax/box_contraction.hpp"

#include <algorithm>
#include <map>

#include "relax/row_reduction.hpp"

namespace hw::relax {

double ContractOrthantBoxes(EngineContext& ctx, const std::vector<Objective>& objectives, const PassOutcomes& pass,
                            std::vector<OrthantWork>& orthants, int order) {
  const bool verify_on = ctx.options.generation.verify.enabled;
  const int n = ctx.set.num_vars();
  double shrink = 0.0;
  for (auto& o : orthants) {
    if (o.empty()) continue;
    Box next = o.box;
    bool crossed = false;
    for (int k = 0; k < n && !crossed; ++k) {
      const double width = next[k].second - next[k].first;
      for (std::size_t j = 0; j < objectives.size(); ++j) {
        if (objectives[j].param != k) continue;
        const auto& r = pass.at({o.index, static_cast<int>(j)});
        if (r.status != "solved" || (verify_on && r.verification != "verified")) continue;
        if (objectives[j].dir < 0) next[k].first = std::max(next[k].first, r.bound);
        else next[k].second = std::min(next[k].second, r.bound);
      }
      if (next[k].first > next[k].second) {
        crossed = true;  // rigorous bounds that cross: no point of the orthant in the box
        break;
      }
      // A box side of (near) zero width would break the scaling: keep a sliver (widening stays valid).
      const auto prior = ctx.set.box()[k];
      const double min_width = 1e-6 * (prior.second - prior.first);
      if (next[k].second - next[k].first < min_width) {
        const double mid = 0.5 * (next[k].first + next[k].second);
        next[k] = {std::max(prior.first, mid - min_width), std::min(prior.second, mid + min_width)};
      }
      shrink = std::max(shrink, 1.0 - (next[k].second - next[k].first) / width);
    }
    if (crossed) {
      // Only verified bounds enter the contraction when verification is on (above).
      o.ProveEmpty({"crossed bounds", order, true, verify_on});
      continue;
    }
    o.box = next;
  }
  return shrink;
}

PassOutcomes ContractBeforeFullPass(EngineContext& ctx, const std::vector<Objective>& objectives,
                                    const PassOutcomes& cheap, std::vector<OrthantWork>& orthants, int cheap_order) {
  std::map<int, std::size_t> position;  // orthant index -> position in `orthants`
  for (std::size_t i = 0; i < orthants.size(); ++i) position[orthants[i].index] = i;
  // The cheap working sets as data-row indices, before the rows change.
  std::map<std::pair<int, int>, std::vector<int>> working_rows;
  for (const auto& [key, r] : cheap) working_rows[key] = RowsOfWorkingSet(orthants[position.at(key.first)], r.working_set);
  std::vector<Box> before;
  for (const auto& w : orthants) before.push_back(w.box);
  ContractOrthantBoxes(ctx, objectives, cheap, orthants, cheap_order);
  std::vector<OrthantWork> moved;
  for (std::size_t i = 0; i < orthants.size(); ++i)
    if (!orthants[i].empty() && orthants[i].box != before[i]) moved.push_back(orthants[i]);
  ReduceOrthantRows(ctx, moved);
  for (const auto& m : moved) orthants[position.at(m.index)] = m;
  PassOutcomes renumbered = cheap;
  for (auto& [key, r] : renumbered)
    if (const auto& w = orthants[position.at(key.first)]; !w.empty()) r.working_set = PositionsOfRows(w, working_rows[key]);
  return renumbered;
}

}  // namespace hw::relax
