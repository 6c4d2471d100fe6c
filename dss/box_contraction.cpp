#include "dss/box_contraction.hpp"

#include <algorithm>
#include <map>

#include "dss/row_reduction.hpp"

namespace hw::dss {

double ContractOrthantBoxes(EngineContext& ctx, const std::vector<Objective>& objectives, const PassOutcomes& pass,
                            std::vector<OrthantWork>& orthants, int order) {
  const bool verify_on = ctx.settings.verify();
  const int n = ctx.set.num_vars();
  double shrink = 0.0;
  for (auto& o : orthants) {
    if (o.empty()) continue;
    ParameterBox next = o.box;
    bool crossed = false;
    for (int k = 0; k < n && !crossed; ++k) {
      const double width = next[k].second - next[k].first;
      for (std::size_t j = 0; j < objectives.size(); ++j) {
        if (objectives[j].param != k) continue;
        const auto& r = pass.at({o.index, static_cast<int>(j)});
        if (r.status != JobStatus::kSolved || (verify_on && r.verification != sdp::VerifyStatus::kVerified)) continue;
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
      o.ProveEmpty({CertificateKind::kCrossedBounds, order, true, verify_on});
      continue;
    }
    o.box = next;
  }
  return shrink;
}

std::set<int> ContractAndReduceRows(EngineContext& ctx, const std::vector<Objective>& objectives,
                                    PassOutcomes& outcomes, const std::set<int>& subset,
                                    std::vector<OrthantWork>& orthants, int order) {
  std::map<int, std::size_t> position;  // orthant index -> position in `orthants`
  for (std::size_t i = 0; i < orthants.size(); ++i) position[orthants[i].index] = i;
  // Copies of the subset's live orthants, contracted; installed once their rows are reduced.
  std::vector<OrthantWork> next;
  for (int l : subset)
    if (!orthants[position.at(l)].empty()) next.push_back(orthants[position.at(l)]);
  ContractOrthantBoxes(ctx, objectives, outcomes, next, order);
  std::vector<OrthantWork> moved;
  for (const auto& w : next) {
    OrthantWork& current = orthants[position.at(w.index)];
    if (w.empty()) current.ProveEmpty(*w.certificate);  // verified bounds that cross
    else if (w.box != current.box) moved.push_back(w);
  }
  if (!moved.empty()) ReduceOrthantRows(ctx, moved);
  std::set<int> moved_index;
  for (const auto& w : moved) {
    OrthantWork& current = orthants[position.at(w.index)];
    for (auto& [key, r] : outcomes)  // each working set keeps its data rows, at their new positions
      if (key.first == w.index) r.working_set = PositionsOfRows(w, RowsOfWorkingSet(current, r.working_set));
    current = w;
    moved_index.insert(w.index);
  }
  return moved_index;
}

void ContractBeforeFullPass(EngineContext& ctx, PipelineState& state, int cheap_order) {
  std::set<int> live;
  for (const auto& w : state.orthants)
    if (!w.empty()) live.insert(w.index);
  ContractAndReduceRows(ctx, state.objectives, state.cheap, live, state.orthants, cheap_order);
}

}  // namespace hw::dss
