#pragma once
// Branch and bound over the dynamics (a_1..a_na) for the exact set D: the two searches of the engine.
//  - PruneLevel: one level of the pruning search: every live box is halved along its relatively widest a_i
//    and each half is tested for emptiness (exact/box_evaluation.hpp). Levels repeat until the live boxes are
//    small against their hull (PruneStop).
//  - SearchObjective: best-first refinement of one endpoint over the live boxes: the box holding the worst
//    bound is bounded by an LP, or halved when it already was, until the bound is within a target of a known
//    point of D, or the LP budget is spent. Its result is the worst bound over the boxes left, so a box is
//    only ever dropped with a certificate.
// Both are pure functions of their inputs (no timing, no worker identity), so any executor gives the same
// numbers.
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "exact/box_evaluation.hpp"

namespace hw::exact {

// The index (in the layout) of the a_i to halve: the widest relative to the start box's width.
int SplitParameter(const LiftedData& data, const ParamBox& box, const ParamBox& start);
// The box cut in two at `cut` along one parameter; HalveBox cuts at the middle.
std::pair<ParamBox, ParamBox> CutBox(const ParamBox& box, int parameter, double cut);
std::pair<ParamBox, ParamBox> HalveBox(const ParamBox& box, int parameter);
// The hull of boxes (per parameter).
ParamBox HullOf(const std::vector<ParamBox>& boxes);

struct PruneStop {
  int max_levels = 80;       // levels of halving
  int max_boxes = 48;        // live boxes: past this the search stops halving
  double resolution = 2.0;   // stop once every live box is at most 1/resolution of the live hull in every a_i
  bool IsValid(std::string* error) const;
};
// Whether the pruning search has reached its stop (boxes small against their hull, or a limit).
bool PruneSearchDone(const LiftedData& data, const std::vector<ParamBox>& live, int level, const PruneStop& stop);

// What an endpoint's refinement halves once a box's LP bound is known.
enum class EndpointSplit {
  kDynamics,   // the a_i only (the relaxation's products a_i z_{t-i} tighten)
  kAlternate,  // the a_i and the endpoint's own parameter in turn: a slab beyond the inner hull is cut off, and a
               // narrow gamma_k ties every beta_jk = b_j gamma_k (the input side's over-parametrisation)
  kFamily,     // the a_i and forms and the entries of the endpoint's own family (exact_endpoint_probe): the gammas
               // for a gamma, the alphas and b's for an alpha or a b; the entry widest against D's known extent
               // (the inner hull's range; else the search's start) first
  kDynamicsGamma,  // as kDynamics, except that an a_i endpoint halves the a_i, forms and gammas, the widest against
                   // D's known extent first: where the LP overreaches D along its strip it rests on beta = b*gamma
                   // (docs/exact_set.md, "An a_i endpoint's bulge")
};
std::string ToString(EndpointSplit split);
bool ParseEndpointSplit(const std::string& text, EndpointSplit* split);
// The entry an endpoint of parameter p halves under `split` (kAlternate's objective cuts aside); `scale` as for
// SearchObjective.
int SplitEntry(const LiftedData& data, const ParamBox& box, const ParamBox& start, int p, EndpointSplit split,
               const ParamBox* scale = nullptr);

struct ObjectiveSearchOptions {
  int lp_budget = 10;              // LPs of one endpoint's refinement (per sweep)
  EndpointSplit split = EndpointSplit::kDynamics;
  GammaRatio gamma_ratio = GammaRatio::kLargest;  // how a gamma's bound divides by the b_j (box_evaluation.hpp)
  double min_relative_width = 1e-9;  // a box narrower than this (relative to the start box) is not halved
  bool IsValid(std::string* error) const;
};

struct ObjectiveSearchResult {
  double bound = 0.0;          // rigorous: no point of D in the boxes is beyond it
  double lp_value = 0.0;       // the floating-point LP value of the box attaining the bound
  bool from_lp = false;        // false: the bound is an edge of a box that no LP tightened
  bool empty = false;          // every box was proven empty
  int lps = 0, lp_failures = 0, boxes_pruned = 0, boxes_left = 0;
  std::vector<PruneCertificate> certificates;
  std::vector<double> point;   // the LP point of the box attaining the bound
  double seconds = 0.0;
  nlohmann::json to_json() const;
  static ObjectiveSearchResult from_json(const nlohmann::json& j);
};

// `target`: a value of the objective at a known point of D (the inner hull); the search stops when the bound
// is within `target_gap` of it. Without a target it spends its budget. `scale` (optional): D's known extent per
// entry (the inner hull's ranges), against which EndpointSplit::kFamily and kDynamicsGamma measure a box's widths.
ObjectiveSearchResult SearchObjective(const LiftedData& data, const ParamBox& start, const std::vector<ParamBox>& boxes,
                                      const Objective& objective, std::optional<double> target, double target_gap,
                                      const ObjectiveSearchOptions& options, const BoxEvaluationOptions& evaluation,
                                      LpSolver& solver, const ParamBox* scale = nullptr);

nlohmann::json BoxToJson(const ParamBox& box);
ParamBox BoxFromJson(const nlohmann::json& j);

}  // namespace hw::exact
