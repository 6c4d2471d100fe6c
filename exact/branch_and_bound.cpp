#include "exact/branch_and_bound.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <tuple>

#include "exact/enum_names.hpp"

namespace hw::exact {

namespace {

// The entry of `entries` (the first of equals) whose width in `box` is the largest against its width in
// `reference`; a point-like reference width counts as a millionth of the start's.
int WidestAgainst(const std::vector<int>& entries, const ParamBox& box, const ParamBox& reference,
                  const ParamBox& start) {
  int best = entries.front();
  double best_ratio = -1.0;
  for (int k : entries) {
    const double extent = std::max(reference[k].hi - reference[k].lo, 1e-6 * (start[k].hi - start[k].lo));
    const double ratio = (box[k].hi - box[k].lo) / extent;
    if (ratio > best_ratio) best_ratio = ratio, best = k;
  }
  return best;
}

// Whether layout entry p is one of the a_i.
bool IsDynamicsCoefficient(const LiftedData& data, int p) {
  return p >= data.layout.a_begin && p < data.layout.a_begin + data.structure.na;
}

// The dynamics' entries: the dynamics forms first (on a tie the cut across D's strip removes more), then the a_i.
std::vector<int> DynamicsEntries(const LiftedData& data, std::size_t box_size) {
  const auto& lay = data.layout;
  std::vector<int> entries;
  for (int k = lay.count(); k < static_cast<int>(box_size); ++k)
    if (IsDynamicsEntry(data, k)) entries.push_back(k);
  for (int i = 0; i < data.structure.na; ++i) entries.push_back(lay.a_begin + i);
  return entries;
}

// The entries an endpoint of parameter p halves with EndpointSplit::kFamily (the dynamics' and p's family) or
// kDynamicsGamma (the dynamics', and the gammas for an a_i).
std::vector<int> FamilyEntries(const LiftedData& data, int p, EndpointSplit split, std::size_t box_size) {
  const auto& lay = data.layout;
  auto in = [](int k, int begin, int count) { return k >= begin && k < begin + count; };
  const int nb = lay.count() - lay.b_begin;
  std::vector<int> entries = DynamicsEntries(data, box_size);
  auto add = [&](int begin, int count) {
    for (int k = begin; k < begin + count; ++k) entries.push_back(k);
  };
  if (split == EndpointSplit::kDynamicsGamma && IsDynamicsCoefficient(data, p)) add(lay.gamma_begin, lay.num_gamma);
  if (split == EndpointSplit::kFamily && in(p, lay.gamma_begin, lay.num_gamma)) add(lay.gamma_begin, lay.num_gamma);
  if (split == EndpointSplit::kFamily && (in(p, lay.alpha_begin, lay.num_alpha) || in(p, lay.b_begin, nb))) {
    add(lay.alpha_begin, lay.num_alpha);
    add(lay.b_begin, nb);
  }
  return entries;
}

}  // namespace

int SplitParameter(const LiftedData& data, const ParamBox& box, const ParamBox& start) {
  return WidestAgainst(DynamicsEntries(data, box.size() == start.size() ? box.size() : 0), box, start, start);
}

int SplitEntry(const LiftedData& data, const ParamBox& box, const ParamBox& start, int p, EndpointSplit split,
               const ParamBox* scale) {
  const bool dynamics_gamma = split == EndpointSplit::kDynamicsGamma && IsDynamicsCoefficient(data, p);
  if (split != EndpointSplit::kFamily && !dynamics_gamma) return SplitParameter(data, box, start);
  const ParamBox& reference = scale && scale->size() == box.size() ? *scale : start;
  return WidestAgainst(FamilyEntries(data, p, split, std::min(box.size(), start.size())), box, reference, start);
}

std::pair<ParamBox, ParamBox> CutBox(const ParamBox& box, int parameter, double cut) {
  ParamBox lower = box, upper = box;
  lower[parameter].hi = cut;
  upper[parameter].lo = cut;
  return {lower, upper};
}

std::pair<ParamBox, ParamBox> HalveBox(const ParamBox& box, int parameter) {
  return CutBox(box, parameter, box[parameter].mid());
}

ParamBox HullOf(const std::vector<ParamBox>& boxes) {
  ParamBox hull = boxes.front();
  for (const auto& b : boxes)
    for (std::size_t k = 0; k < hull.size(); ++k) hull[k] = Hull(hull[k], b[k]);
  return hull;
}

bool PruneStop::IsValid(std::string* error) const {
  if (max_levels < 0 || max_boxes < 1 || !(resolution >= 1.0)) {
    if (error) *error = "pruning stop: max_levels >= 0, max_boxes >= 1 and resolution >= 1 are required";
    return false;
  }
  return true;
}

bool PruneSearchDone(const LiftedData& data, const std::vector<ParamBox>& live, int level, const PruneStop& stop) {
  if (live.empty() || level >= stop.max_levels || static_cast<int>(live.size()) > stop.max_boxes) return true;
  const ParamBox hull = HullOf(live);
  const auto& lay = data.layout;
  for (const auto& box : live)
    for (int i = 0; i < data.structure.na; ++i) {
      const int k = lay.a_begin + i;
      if ((box[k].hi - box[k].lo) * stop.resolution > (hull[k].hi - hull[k].lo)) return false;
    }
  return true;
}

std::string ToString(EndpointSplit split) {
  switch (split) {
    case EndpointSplit::kDynamics: return "dynamics";
    case EndpointSplit::kAlternate: return "alternate";
    case EndpointSplit::kFamily: return "family";
    case EndpointSplit::kDynamicsGamma: return "dynamics-gamma";
  }
  return "dynamics";
}

bool ParseEndpointSplit(const std::string& text, EndpointSplit* split) {
  return ParseByName(text, {EndpointSplit::kDynamics, EndpointSplit::kAlternate, EndpointSplit::kFamily,
                                EndpointSplit::kDynamicsGamma}, split);
}

bool ObjectiveSearchOptions::IsValid(std::string* error) const {
  if (lp_budget < 1 || !(min_relative_width > 0)) {
    if (error) *error = "objective search: lp_budget >= 1 and min_relative_width > 0 are required";
    return false;
  }
  return true;
}

nlohmann::json ObjectiveSearchResult::to_json() const {
  nlohmann::json certs = nlohmann::json::array();
  for (const auto& c : certificates) certs.push_back(c.to_json());
  return {{"bound", bound}, {"lp_value", lp_value}, {"from_lp", from_lp}, {"empty", empty}, {"lps", lps},
          {"lp_failures", lp_failures}, {"boxes_pruned", boxes_pruned}, {"boxes_left", boxes_left},
          {"certificates", certs}, {"point", point}, {"seconds", seconds}};
}

ObjectiveSearchResult ObjectiveSearchResult::from_json(const nlohmann::json& j) {
  ObjectiveSearchResult r;
  r.bound = j.at("bound").get<double>();
  r.lp_value = j.at("lp_value").get<double>();
  r.from_lp = j.at("from_lp").get<bool>();
  r.empty = j.at("empty").get<bool>();
  r.lps = j.at("lps").get<int>();
  r.lp_failures = j.at("lp_failures").get<int>();
  r.boxes_pruned = j.at("boxes_pruned").get<int>();
  r.boxes_left = j.at("boxes_left").get<int>();
  for (const auto& c : j.at("certificates")) r.certificates.push_back(PruneCertificate::from_json(c));
  r.point = j.at("point").get<std::vector<double>>();
  r.seconds = j.at("seconds").get<double>();
  return r;
}

nlohmann::json BoxToJson(const ParamBox& box) {
  nlohmann::json j = nlohmann::json::array();
  for (const auto& iv : box) j.push_back({iv.lo, iv.hi});
  return j;
}

ParamBox BoxFromJson(const nlohmann::json& j) {
  ParamBox box;
  for (const auto& iv : j) box.emplace_back(iv.at(0).get<double>(), iv.at(1).get<double>());
  return box;
}

namespace {

struct SearchBox {
  ParamBox box;
  double bound = 0.0;      // in minimisation terms: sign * objective >= bound over the box
  bool evaluated = false;  // an LP tightened (or confirmed) the bound on this very box
  bool from_lp = false;
  double lp_value = 0.0;
  std::vector<double> point;
  LpBasis basis;
  int objective_splits = 0, dynamics_splits = 0;  // along the box's lineage
};

// Where to cut the objective's own range [lo, hi] (hi: the box's proven bound, in maximisation terms): with a
// point of D at `target` inside, just far enough beyond it that cutting off the far slab would end the search
// (or halfway to the bound, whichever is farther); else the middle.
double ObjectiveCut(Interval range, bool maximise, std::optional<double> target, double target_gap) {
  if (!target || !(*target > range.lo && *target < range.hi)) return range.mid();
  const double room = maximise ? range.hi - *target : *target - range.lo;
  const double step = std::max(0.5 * room, std::min(target_gap, 0.75 * room));
  return maximise ? *target + step : *target - step;
}

}  // namespace

ObjectiveSearchResult SearchObjective(const LiftedData& data, const ParamBox& start, const std::vector<ParamBox>& boxes,
                                      const Objective& objective, std::optional<double> target, double target_gap,
                                      const ObjectiveSearchOptions& options, const BoxEvaluationOptions& evaluation,
                                      LpSolver& solver, const ParamBox* scale) {
  const auto t0 = std::chrono::steady_clock::now();
  const double sign = objective.maximise ? -1.0 : 1.0;
  const int p = objective.parameter;
  std::vector<SearchBox> live;
  for (const auto& b : boxes) live.push_back({b, objective.maximise ? -b[p].hi : b[p].lo});
  // An LP bound within a hundredth of the stopping gap is as good as the exact optimum for this search.
  BoxEvaluationOptions accuracy = evaluation;
  if (target && target_gap > 0) accuracy.lp.acceptable_gap = 0.01 * target_gap;
  ObjectiveSearchResult out;
  while (!live.empty()) {
    // The box holding the worst bound (the first of equals: deterministic).
    std::size_t w = 0;
    for (std::size_t i = 1; i < live.size(); ++i)
      if (live[i].bound < live[w].bound) w = i;
    SearchBox& box = live[w];
    if (!box.evaluated) {
      if (out.lps >= options.lp_budget) break;
      // With kRotate children divide a gamma by the next b_j: a box keeps the tighter of its own and its parent's bound.
      const int turn = box.objective_splits + box.dynamics_splits;
      const std::optional<double> ratio_start = box.from_lp ? std::optional<double>(box.lp_value) : std::nullopt;
      BoxEvaluation e =
          BoundObjective(data, box.box, objective, accuracy, solver, box.basis, options.gamma_ratio, turn, ratio_start);
      out.lps += e.lps;
      out.lp_failures += e.lp_failures;
      if (e.verdict == BoxVerdict::kPruned) {
        out.certificates.push_back(*e.certificate);
        ++out.boxes_pruned;
        live.erase(live.begin() + static_cast<long>(w));
        continue;
      }
      box.evaluated = true;
      if (e.bound && sign * *e.bound > box.bound) {
        box.bound = sign * *e.bound;
        box.from_lp = true;
        box.lp_value = e.lp_value;
      }
      // No point of D in the box lies beyond its bound: the box shrinks to it (tighter envelopes for children).
      if (e.bound) {
        Interval& r = box.box[p];
        if (objective.maximise) r.hi = std::max(r.lo, std::min(r.hi, *e.bound));
        else r.lo = std::min(r.hi, std::max(r.lo, *e.bound));
      }
      if (!e.point.empty()) box.point = e.point;
      if (!e.basis.empty()) box.basis = e.basis;
      continue;
    }
    if (target && box.bound >= sign * *target - target_gap) break;  // within the target of a point of D
    if (out.lps >= options.lp_budget) break;
    const bool is_dynamics = IsDynamicsEntry(data, p);
    const bool cut_objective = options.split == EndpointSplit::kAlternate && !is_dynamics &&
                               box.objective_splits <= box.dynamics_splits;
    const int k = cut_objective ? p : SplitEntry(data, box.box, start, p, options.split, scale);
    if (box.box[k].hi - box.box[k].lo < options.min_relative_width * (start[k].hi - start[k].lo)) break;
    const double cut = cut_objective ? ObjectiveCut(box.box[p], objective.maximise, target, target_gap)
                                     : box.box[k].mid();
    SearchBox a = box, b = box;
    a.evaluated = b.evaluated = false;
    std::tie(a.box, b.box) = CutBox(box.box, k, cut);
    for (SearchBox* c : {&a, &b}) {
      PropagateForms(data, c->box);
      (cut_objective ? c->objective_splits : c->dynamics_splits) += 1;
      // A child cut in the objective's range can reach no farther than its own edge.
      const double edge = objective.maximise ? -c->box[p].hi : c->box[p].lo;
      if (cut_objective && edge > c->bound) {
        c->bound = edge;  // proven by the sibling's answer, once the sibling is done
        c->lp_value = sign * edge;
      }
    }
    live.erase(live.begin() + static_cast<long>(w));
    live.insert(live.begin() + static_cast<long>(w), {a, b});
  }
  out.boxes_left = static_cast<int>(live.size());
  if (live.empty()) {
    out.empty = true;
  } else {
    std::size_t w = 0;
    for (std::size_t i = 1; i < live.size(); ++i)
      if (live[i].bound < live[w].bound) w = i;
    out.bound = sign * live[w].bound;
    out.from_lp = live[w].from_lp;
    out.lp_value = live[w].from_lp ? live[w].lp_value : out.bound;
    out.point = live[w].point;
  }
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return out;
}

}  // namespace hw::exact
