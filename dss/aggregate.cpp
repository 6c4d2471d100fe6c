#include "dss/aggregate.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

namespace hw::dss {
namespace {

int objective_index(const std::vector<Objective>& objectives, int param, int dir) {
  for (std::size_t i = 0; i < objectives.size(); ++i)
    if (objectives[i].param == param && objectives[i].dir == dir) return static_cast<int>(i);
  throw std::logic_error("objective not in the list");
}

// One orthant's contribution to an endpoint.
struct OrthantValue {
  double value = 0.0, float_value = 0.0;
  std::string status = "guaranteed", note, verification, source;
  bool tight = false;
};

OrthantValue ValueOf(const AggregateOptions& options, const JobOutcome& r, const JobOutcome& c, const OrthantWork& w,
                     int param, int dir) {
  OrthantValue v;
  if (r.status == "solved" || r.status == "skipped") {
    v.value = r.bound;
    v.float_value = r.float_bound;
    v.verification = r.verification;
    v.tight = r.tight;
    v.source = r.unfinished ? "unfinished solve" : r.origin == "earlier round" ? "earlier round" : "final round";
    if (r.beyond_known_value) v.source = "stopped beyond a feasible point's value (cannot move the interval)";
    if (r.status == "skipped") v.source = "cheap order (cannot move the interval)";
    if (r.origin == "feasible point at the box edge" || r.origin == "box edge reached in another orthant" ||
        r.origin == "orthant sign constraint")
      v.source = r.origin;
    // Both orders bound the same orthant, so the tighter one holds: an order-delta job that stopped short
    // (unfinished solve, round limit) can end looser than the cheap order's bound.
    const bool from_sdp = r.status == "solved" && (r.origin == "final round" || r.origin == "earlier round");
    const bool cheap_tighter = dir < 0 ? c.bound > r.bound : c.bound < r.bound;
    if (from_sdp && options.order > options.cheap_order && c.status == "solved" && cheap_tighter &&
        (c.verification == r.verification || c.verification == "verified")) {
      v.value = c.bound;
      v.float_value = c.float_bound;
      v.verification = c.verification;
      v.tight = false;
      v.source = "cheap order (tighter than an order-delta job that stopped short)";
    }
    return v;
  }
  v.status = "conservative";
  if (c.status == "solved" && options.order > options.cheap_order) {
    v.value = c.bound;
    v.float_value = c.float_bound;
    v.verification = c.verification;
    v.source = "cheap order";
    v.note = fmt::format("order-{} solve failed in orthant {} ({}); order-{} bound used", options.order, w.index,
                         r.message, options.cheap_order);
    return v;
  }
  // The orthant's box edge: the prior box, or a contracted box proven to contain the orthant's points.
  v.value = v.float_value = dir < 0 ? w.box[param].first : w.box[param].second;
  v.verification = options.verify ? "verified" : "off";
  v.source = "box edge";
  v.note = fmt::format("solve failed in orthant {} ({}); box edge used", w.index, r.message);
  return v;
}

Endpoint AggregateEndpoint(const AggregateOptions& options, const std::vector<OrthantWork>& orthants,
                           const PassOutcomes& cheap, const PassOutcomes& full, int o, int param, int dir,
                           std::map<std::string, int>& sources) {
  Endpoint ep;
  ep.status = "empty";
  bool any = false;
  double float_value = 0.0;
  std::string unverified;
  for (const auto& w : orthants) {
    if (w.empty()) continue;
    const auto& r = full.at({w.index, o});
    if (r.status == "infeasible") continue;  // proven empty in this orthant
    const OrthantValue v = ValueOf(options, r, cheap.at({w.index, o}), w, param, dir);
    ++sources[v.source];
    if (options.verify && v.verification != "verified") unverified += (unverified.empty() ? "" : ", ") + std::to_string(w.index);
    if (!any || (dir < 0 ? v.float_value < float_value : v.float_value > float_value)) float_value = v.float_value;
    // The endpoint's status is that of the orthant attaining it: a fallback that is not extreme leaves the
    // endpoint exact, since the fallback still bounds that orthant.
    if (!any || (dir < 0 ? v.value < ep.value : v.value > ep.value)) {
      ep.value = v.value;
      ep.orthant = w.index;
      ep.tight = v.tight;
      ep.status = v.status;
    }
    if (!v.note.empty()) ep.note += (ep.note.empty() ? "" : "; ") + v.note;
    any = true;
  }
  if (!any) {
    ep.note = "every orthant is proven empty";
    return ep;
  }
  ep.verification = !options.verify ? "off" : unverified.empty() ? "verified" : "unverified";
  ep.correction = std::abs(ep.value - float_value);
  if (!unverified.empty())
    ep.note += (ep.note.empty() ? "" : "; ") +
               fmt::format("floating-point bound not verified in orthant(s) {} (value is the solver's)", unverified);
  return ep;
}

}  // namespace

AggregateResult AggregateIntervals(const AggregateOptions& options, const HwOuterSet& set,
                                   const std::vector<Objective>& objectives, const std::vector<int>& wanted_params,
                                   const PassOutcomes& cheap, const PassOutcomes& full,
                                   const std::vector<OrthantWork>& orthants) {
  AggregateResult out;
  for (int k : wanted_params) {
    ParameterInterval iv;
    iv.name = set.layout().names[k];
    for (int dir : {-1, +1}) {
      Endpoint ep = AggregateEndpoint(options, orthants, cheap, full, objective_index(objectives, k, dir), k, dir,
                                      out.sources);
      // The prior box is an assumption of every result: an endpoint beyond it (rounding of the box edge's own
      // relaxation bound) is clipped to it.
      if (ep.status != "empty") {
        const double edge = dir < 0 ? set.box()[k].first : set.box()[k].second;
        if (dir < 0 ? ep.value < edge : ep.value > edge) {
          ep.value = edge;
          out.clipped_to_box = true;
        }
      }
      (dir < 0 ? iv.lower : iv.upper) = ep;
    }
    out.intervals.push_back(iv);
  }
  return out;
}

}  // namespace hw::dss
