// Which range does an endpoint's relaxation bound depend on? On a committed exact-set result (the box it proved,
// its forms), the bound of one endpoint on that box, then on the same box with one entry at a time narrowed to
// a share of its width around the inner hull's point extreme in that endpoint: the entry whose narrowing moves
// the bound most is the one a branch and bound should split for it.
//   exact_endpoint_probe --result paper_examples/results/exact_snr31_seed1/exact.json --parameter gamma2 --max
#include <chrono>
#include <cstdlib>
#include <fstream>

#include <CLI/CLI.hpp>
#include <fmt/format.h>
#include <fmt/ranges.h>
#include <nlohmann/json.hpp>

#include "core/cerone_example.hpp"
#include "dss/hw_outer_set.hpp"
#include "exact/box_evaluation.hpp"
#include "exact/branch_and_bound.hpp"
#include "exact/parameter_forms.hpp"
#include "exact/inner_hull.hpp"
#include "exact/membership.hpp"
#include "exact/lifted_lp.hpp"
#include "exact/lp_solver.hpp"

namespace ex = hw::exact;

namespace {

struct ProbeContext {
  const ex::LiftedData& lifted;
  const ex::BoxEvaluationOptions& options;
  ex::LpSolver& solver;
  ex::GammaRatio ratio;
};

// The slab of the endpoint's own range beyond extreme + share * (bound - extreme): is it empty, or how far does it
// reach, once every other parameter's range is bounded inside it by LPs (`rounds` times)?
void ProbeSlab(const ProbeContext& c, ex::ParamBox box, const ex::Objective& objective, double extreme, double bound,
               double share, int rounds) {
  const auto& names = c.lifted.layout.names;
  const int p = objective.parameter;
  const double cut = extreme + share * (bound - extreme);
  box[p] = objective.maximise ? ex::Interval(cut, bound) : ex::Interval(bound, cut);
  int lps = 0;
  for (int round = 1; round <= rounds; ++round) {
    for (int k = 0; k < c.lifted.layout.count(); ++k) {
      if (k == p) continue;
      const double before = box[k].hi - box[k].lo;
      for (bool up : {false, true}) {
        const auto e = ex::BoundObjective(c.lifted, box, ex::Objective{k, up}, c.options, c.solver, {}, c.ratio);
        lps += e.lps;
        if (e.verdict == ex::BoxVerdict::kPruned) {
          fmt::print("round {}: the slab beyond {:.7f} is empty (pruned while bounding {}), {} LPs\n", round, cut,
                     names[k], lps);
          return;
        }
        if (!e.bound) continue;
        if (up) box[k].hi = std::max(box[k].lo, std::min(box[k].hi, *e.bound));
        else box[k].lo = std::min(box[k].hi, std::max(box[k].lo, *e.bound));
      }
      ex::PropagateForms(c.lifted, box);
      fmt::print("round {}: {} keeps {:.2f} of its width in the slab\n", round, names[k], (box[k].hi - box[k].lo) / before);
    }
    const auto e = ex::BoundObjective(c.lifted, box, objective, c.options, c.solver, {}, c.ratio);
    lps += e.lps;
    const double b = e.bound ? *e.bound : NAN;
    fmt::print("round {}: slab beyond {:.7f}: bound {:.7f} ({:.0f} % of the gap closed), {} LPs so far\n", round, cut, b,
               100 * (1 - std::abs(b - extreme) / std::abs(bound - extreme)), lps);
  }
}


// D's known extent per entry: the inner hull's range (the box's own range for a form or an entry without one).
ex::ParamBox InnerExtent(const ex::InnerHull& hull, const ex::ParamBox& box) {
  ex::ParamBox extent = box;
  for (std::size_t k = 0; k < hull.ranges.size() && k < box.size(); ++k)
    if (hull.ranges[k]) extent[k] = ex::Interval(hull.ranges[k]->first, hull.ranges[k]->second);
  return extent;
}

// One endpoint search as a sweep runs it (from the whole box, towards the inner extreme within the default
// target's allowance): how far a budget of LPs gets under a split rule.
void ProbeSearch(const ProbeContext& c, const ex::ParamBox& box, const ex::Objective& objective, double extreme,
                 const ex::ParamBox& extent, int budget, ex::EndpointSplit split) {
  const int p = objective.parameter;
  const double width = extent[p].hi - extent[p].lo;
  ex::ObjectiveSearchOptions search;
  search.lp_budget = budget;
  search.split = split;
  const auto t0 = std::chrono::steady_clock::now();
  const auto r = ex::SearchObjective(c.lifted, box, {box}, objective, extreme, 0.125 * width, search, c.options,
                                     c.solver, &extent);
  fmt::print("search ({}): bound {:.7f}, gap to inner {:.3g} = {:.3f} of the inner width, {} LPs, {} boxes left, {:.1f} s\n",
             ex::ToString(split), r.bound, std::abs(r.bound - extreme), std::abs(r.bound - extreme) / width, r.lps,
             r.boxes_left, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
}

// The endpoint's bound in each of `count` equal slices of entry `along`, with the membership slack of each
// slice's LP point (its parameter values, checked exactly; negative: outside D).
void ProbeSlices(const ProbeContext& c, const ex::ParamBox& box, const ex::Objective& objective, int along, int count) {
  const auto& lay = c.lifted.layout;
  const double w = (box[along].hi - box[along].lo) / count;
  for (int i = 0; i < count; ++i) {
    ex::ParamBox b = box;
    b[along] = ex::Interval(box[along].lo + i * w, box[along].lo + (i + 1) * w);
    ex::PropagateForms(c.lifted, b);
    const auto e = ex::BoundObjective(c.lifted, b, objective, c.options, c.solver, {}, c.ratio);
    if (e.verdict == ex::BoxVerdict::kPruned || !e.bound || e.point.size() < static_cast<std::size_t>(lay.count())) {
      fmt::print("slice [{:.7f}, {:.7f}]: {}\n", b[along].lo, b[along].hi,
                 e.verdict == ex::BoxVerdict::kPruned ? "empty (pruned)" : "no bound");
      continue;
    }
    const std::vector<double> theta(e.point.begin(), e.point.begin() + lay.count());
    const auto m = ex::CheckMembership(c.lifted, theta, c.solver);
    fmt::print("slice [{:.7f}, {:.7f}]: bound {:.7f}, its LP point's membership slack {:.3g}\n", b[along].lo, b[along].hi,
               *e.bound, m.slack);
  }
}
// Gain and shape forms from the inner hull's points (as a run with them would make), appended to the data's
// forms; the box gets their ranges bounded by one LP per end (a run bounds them in the forms' sweep).
void AddInputForms(ex::LiftedData& lifted, const ex::InnerHull& hull, const std::vector<std::string>& blocks,
                   ex::ParamBox& box, const ex::BoxEvaluationOptions& options, ex::LpSolver& solver,
                   ex::GammaRatio ratio) {
  ex::FormOptions fo;
  for (const auto& b : blocks) {
    if (b == "gain") fo.gain = true;
    else if (b == "shape") fo.shape = true;
    else throw std::invalid_argument("--add-forms: gain or shape, not " + b);
  }
  std::vector<std::vector<double>> points;
  for (const auto& pt : hull.points) points.push_back(pt.theta);
  box = ex::WithFormRanges(lifted, box);
  for (const auto& f : ex::ThinDirections(lifted, points, fo)) {
    if (f.block == ex::FormBlock::kDynamics) continue;
    lifted.forms.push_back(f);
    box.push_back(ex::FormRange(lifted, f, box));
    const int k = static_cast<int>(box.size()) - 1;
    for (bool up : {false, true}) {
      const auto e = ex::BoundObjective(lifted, box, ex::Objective{k, up}, options, solver, {}, ratio);
      if (e.bound && up) box[k].hi = std::min(box[k].hi, *e.bound);
      if (e.bound && !up) box[k].lo = std::max(box[k].lo, *e.bound);
    }
    fmt::print("{} form [{}]: range [{:.7g}, {:.7g}]\n", ex::ToString(f.block), fmt::join(f.coef, ", "), box[k].lo,
               box[k].hi);
  }
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Sensitivity of an exact-set endpoint's LP bound to each range of the box"};
  std::string result_path, parameter = "gamma2", solver_name = "ipm", ratio_name = "largest";
  bool maximise = false;
  double share = 0.1;
  app.add_option("--result", result_path, "exact.json of a committed exact_tables run (seed and N from it)")->required();
  app.add_option("--parameter", parameter, "the endpoint's parameter");
  app.add_flag("--max", maximise, "the upper endpoint (default: the lower)");
  app.add_option("--share", share, "each narrowed range keeps this share of its width")->check(CLI::Range(1e-6, 1.0));
  app.add_option("--lp-solver", solver_name);
  app.add_option("--gamma-ratio", ratio_name);
  bool bound_only = false, start_box = false;
  double slab = 0.0;
  int rounds = 2;
  app.add_option("--slab", slab,
                 "instead of narrowing: the slab of the endpoint's own range beyond the inner extreme plus this "
                 "share of the gap; every other parameter bounded in it by LPs, then the endpoint, for --rounds")
      ->check(CLI::Range(0.0, 1.0));
  app.add_option("--rounds", rounds, "with --slab: rounds of bounding every other parameter in the slab");
  app.add_flag("--start-box", start_box, "the run's start box (the D^ss box) instead of the box it proved");
  app.add_flag("--bound-only", bound_only, "the whole box's bound only (no narrowing)");
  int search_budget = 0;
  app.add_option("--search", search_budget, "instead of narrowing: one endpoint search (SearchObjective) with this LP budget");
  std::string split_name = "dynamics", slices;
  app.add_option("--split", split_name, "with --search: what the search halves (as exact_tables --split)");
  app.add_option("--slices", slices, "NAME:K instead of narrowing: the bound in each of K equal slices of NAME's range");
  std::vector<std::string> pinned;
  app.add_option("--pin", pinned, "entries fixed at the inner extreme's values (to 1e-7 relative) before probing")
      ->delimiter(',');
  std::vector<std::string> add_forms;
  app.add_option("--add-forms", add_forms,
                 "gain,shape: forms over the b_j / the gammas from the inner hull's points, their ranges bounded by "
                 "two LPs each on the box before probing")
      ->delimiter(',');
  CLI11_PARSE(app, argc, argv);
  std::ifstream in(result_path);
  const nlohmann::json j = nlohmann::json::parse(in);
  const auto& real = j.at("realisation");
  const auto ex_data = hw::SimulateCeroneExample(real.at("seed").get<uint64_t>(), real.at("samples").get<int>(),
                                                 real.at("snr_db").get<double>());
  hw::dss::HwData data{ex_data.u, ex_data.y, std::vector<double>(ex_data.y.size(), ex_data.noise_bound), "probe"};
  auto lifted = ex::MakeLiftedData(hw::dss::CeroneExampleStructure(), data);
  const auto& stage2 = j.at("stage2");
  lifted.forms = ex::FormsFromJson(stage2.contains("forms") ? stage2.at("forms") : stage2.at("dynamics_forms"));
  ex::ParamBox box;
  if (start_box)
    for (const auto& iv : j.at("start_box")) box.emplace_back(iv.at(0).get<double>(), iv.at(1).get<double>());
  else
    for (const auto& iv : j.at("intervals")) box.emplace_back(iv.at("lower").at("value"), iv.at("upper").at("value"));
  const auto& names = lifted.layout.names;
  const int p = static_cast<int>(std::find(names.begin(), names.end(), parameter) - names.begin());
  if (p >= lifted.layout.count()) throw std::invalid_argument("unknown parameter " + parameter);
  auto solver = ex::MakeLpSolver(solver_name);
  ex::GammaRatio ratio;
  ex::ParseGammaRatio(ratio_name, &ratio);

  // The point of D extreme in the endpoint (inner hull from the truth).
  const auto hull = ex::ComputeInnerHull(lifted, box, hw::CeroneExample::TrueParameters(), ex::InnerHullOptions{}, *solver);
  std::vector<double> extreme;
  for (const auto& pt : hull.points)
    if (extreme.empty() || (maximise ? pt.theta[p] > extreme[p] : pt.theta[p] < extreme[p])) extreme = pt.theta;
  fmt::print("inner extreme of {}: {:.7f}\n", parameter, extreme[p]);
  for (const auto& name : pinned) {
    const int k = static_cast<int>(std::find(names.begin(), names.end(), name) - names.begin());
    if (k >= lifted.layout.count()) throw std::invalid_argument("--pin: unknown parameter " + name);
    box[k] = ex::Interval(extreme[k] - 1e-7 * std::abs(extreme[k]), extreme[k] + 1e-7 * std::abs(extreme[k]));
  }
  ex::BoxEvaluationOptions options;
  if (!add_forms.empty()) AddInputForms(lifted, hull, add_forms, box, options, *solver, ratio);
  box = ex::WithFormRanges(lifted, box);
  ex::PropagateForms(lifted, box);
  const ex::Objective objective{p, maximise};
  auto bound_on = [&](const ex::ParamBox& b) {
    const auto e = ex::BoundObjective(lifted, b, objective, options, *solver, {}, ratio);
    return std::pair{e.bound ? *e.bound : NAN, e.lps};
  };
  const auto t0 = std::chrono::steady_clock::now();
  const auto [b0, lps0] = bound_on(box);
  fmt::print("whole box: bound {:.7f} (gap to inner {:.3g}, {} LPs, {:.2f} s)\n", b0, std::abs(b0 - extreme[p]), lps0,
             std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  if (bound_only) return 0;
  const ProbeContext context{lifted, options, *solver, ratio};
  if (search_budget > 0) {
    ex::EndpointSplit split;
    if (!ex::ParseEndpointSplit(split_name, &split)) throw std::invalid_argument("unknown --split " + split_name);
    ProbeSearch(context, box, objective, extreme[p], InnerExtent(hull, box), search_budget, split);
    return 0;
  }
  if (!slices.empty()) {
    const auto colon = slices.find(':');
    const std::string along = slices.substr(0, colon);
    const int k = static_cast<int>(std::find(names.begin(), names.end(), along) - names.begin());
    if (colon == std::string::npos || k >= lifted.layout.count()) throw std::invalid_argument("--slices NAME:K, NAME a parameter");
    ProbeSlices(context, box, objective, k, std::stoi(slices.substr(colon + 1)));
    return 0;
  }
  if (slab > 0.0) {
    ProbeSlab(context, box, objective, extreme[p], b0, slab, rounds);
    return 0;
  }
  std::vector<double> at = extreme;
  for (const auto& f : lifted.forms) at.push_back(ex::FormValue(lifted, f, extreme));
  auto narrowed = [&](ex::ParamBox b, int k) {
    const double half = 0.5 * share * (b[k].hi - b[k].lo);
    const double c = std::clamp(at[k], b[k].lo + half, b[k].hi - half);
    b[k] = ex::Interval(c - half, c + half);
    ex::PropagateForms(lifted, b);
    return b;
  };
  for (std::size_t k = 0; k < box.size(); ++k) {
    const std::string name = static_cast<int>(k) < lifted.layout.count() ? names[k] : fmt::format("form{}", k - names.size());
    const auto [bk, lps] = bound_on(narrowed(box, static_cast<int>(k)));
    fmt::print("{:>7} narrowed to {:.2g} of its width: bound {:.7f}, gap to inner {:.3g} ({:.0f} % of the gap closed, {} LPs)\n",
               name, share, bk, std::abs(bk - extreme[p]), 100 * (1 - std::abs(bk - extreme[p]) / std::abs(b0 - extreme[p])), lps);
  }
  ex::ParamBox all = box;
  for (std::size_t k = 0; k < box.size(); ++k)
    if (static_cast<int>(k) != p) all = narrowed(all, static_cast<int>(k));
  const auto [ba, lpsa] = bound_on(all);
  fmt::print("every other entry narrowed: bound {:.7f}, gap to inner {:.3g}\n", ba, std::abs(ba - extreme[p]));
  return 0;
}
