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

// Where a solved or skipped job's bound came from.
BoundSource SourceOf(const JobOutcome& r) {
  switch (r.origin) {
    case JobOrigin::kFeasiblePointAtEdge: return BoundSource::kFeasiblePointAtEdge;
    case JobOrigin::kEdgeInOtherOrthant: return BoundSource::kEdgeInOtherOrthant;
    case JobOrigin::kSignConstraint: return BoundSource::kSignConstraint;
    case JobOrigin::kNone:
    case JobOrigin::kFinalRound:
    case JobOrigin::kEarlierRound: break;
  }
  if (r.status == JobStatus::kSkipped) return BoundSource::kCheapOrderSkipped;
  if (r.beyond_known_value) return BoundSource::kStoppedBeyondWitness;
  if (r.unfinished) return BoundSource::kUnfinishedSolve;
  return r.origin == JobOrigin::kEarlierRound ? BoundSource::kEarlierRound : BoundSource::kFinalRound;
}

// One orthant's contribution to an endpoint.
struct OrthantValue {
  double value = 0.0, float_value = 0.0;
  EndpointStatus status = EndpointStatus::kGuaranteed;
  std::string note;
  sdp::VerifyStatus verification = sdp::VerifyStatus::kNotRun;
  BoundSource source = BoundSource::kFinalRound;
  bool tight = false;
};

OrthantValue ValueOf(const AggregateOptions& options, const JobOutcome& r, const JobOutcome& c, const OrthantWork& w,
                     int param, int dir) {
  OrthantValue v;
  if (r.status == JobStatus::kSolved || r.status == JobStatus::kSkipped) {
    v.value = r.bound;
    v.float_value = r.float_bound;
    v.verification = r.verification;
    v.tight = r.tight;
    v.source = SourceOf(r);
    // Both orders bound the same orthant, so the tighter one holds: an order-delta job that stopped short
    // (unfinished solve, round limit) can end looser than the cheap order's bound.
    const bool from_sdp = r.status == JobStatus::kSolved &&
                          (r.origin == JobOrigin::kFinalRound || r.origin == JobOrigin::kEarlierRound);
    const bool cheap_tighter = dir < 0 ? c.bound > r.bound : c.bound < r.bound;
    if (from_sdp && options.order > options.cheap_order && c.status == JobStatus::kSolved && cheap_tighter &&
        (c.verification == r.verification || c.verification == sdp::VerifyStatus::kVerified)) {
      v.value = c.bound;
      v.float_value = c.float_bound;
      v.verification = c.verification;
      v.tight = false;
      v.source = BoundSource::kCheapOrderTighter;
    }
    return v;
  }
  v.status = EndpointStatus::kConservative;
  if (c.status == JobStatus::kSolved && options.order > options.cheap_order) {
    v.value = c.bound;
    v.float_value = c.float_bound;
    v.verification = c.verification;
    v.source = BoundSource::kCheapOrder;
    v.note = fmt::format("order-{} solve failed in orthant {} ({}); order-{} bound used", options.order, w.index,
                         r.message, options.cheap_order);
    return v;
  }
  // The orthant's box edge: the prior box, or a contracted box proven to contain the orthant's points.
  v.value = v.float_value = dir < 0 ? w.box[param].first : w.box[param].second;
  v.verification = options.verify ? sdp::VerifyStatus::kVerified : sdp::VerifyStatus::kNotRun;
  v.source = BoundSource::kBoxEdge;
  v.note = fmt::format("solve failed in orthant {} ({}); box edge used", w.index, r.message);
  return v;
}

Endpoint AggregateEndpoint(const AggregateOptions& options, const std::vector<OrthantWork>& orthants,
                           const PassOutcomes& cheap, const PassOutcomes& full, int o, int param, int dir,
                           std::map<BoundSource, int>& sources) {
  Endpoint ep;
  ep.status = EndpointStatus::kEmpty;
  bool any = false;
  double float_value = 0.0;
  std::string unverified;
  for (const auto& w : orthants) {
    if (w.empty()) continue;
    const auto& r = full.at({w.index, o});
    if (r.status == JobStatus::kInfeasible) continue;  // proven empty in this orthant
    const OrthantValue v = ValueOf(options, r, cheap.at({w.index, o}), w, param, dir);
    ++sources[v.source];
    if (options.verify && v.verification != sdp::VerifyStatus::kVerified) unverified += (unverified.empty() ? "" : ", ") + std::to_string(w.index);
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
  ep.verification = !options.verify      ? sdp::VerifyStatus::kNotRun
                    : unverified.empty() ? sdp::VerifyStatus::kVerified
                                         : sdp::VerifyStatus::kUnverified;
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
      if (ep.status != EndpointStatus::kEmpty) {
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
