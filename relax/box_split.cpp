#include "relax/box_split.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <set>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "core/csv_table.hpp"

namespace hw::relax {
namespace {

bool Fail(std::string* error, std::string message) {
  if (error) *error = std::move(message);
  return false;
}

std::size_t IndexOf(const std::vector<std::string>& names, const std::string& name) {
  return std::find(names.begin(), names.end(), name) - names.begin();
}

// The slabs of one side [lo, hi] cut at the sorted values.
std::vector<std::pair<double, double>> Slabs(std::pair<double, double> side, std::vector<double> values) {
  std::sort(values.begin(), values.end());
  std::vector<std::pair<double, double>> slabs;
  double lo = side.first;
  for (double v : values) {
    slabs.push_back({lo, v});
    lo = v;
  }
  slabs.push_back({lo, side.second});
  return slabs;
}

// The outermost endpoint over the live pieces (dir -1: lower, +1: upper), with the weakest status of them.
Endpoint OutermostEndpoint(const std::vector<const Endpoint*>& endpoints, const std::vector<int>& piece_of, int dir) {
  std::size_t best = 0;
  for (std::size_t i = 1; i < endpoints.size(); ++i)
    if (dir < 0 ? endpoints[i]->value < endpoints[best]->value : endpoints[i]->value > endpoints[best]->value) best = i;
  Endpoint out = *endpoints[best];
  if (!out.note.empty()) out.note = fmt::format("piece {}: {}", piece_of[best] + 1, out.note);
  bool all_verified = true, any_unverified = false;
  for (const Endpoint* e : endpoints) {
    if (e->status != "guaranteed") out.status = "conservative";
    out.tight = out.tight && e->tight;
    out.correction = std::max(out.correction, e->correction);
    all_verified = all_verified && e->verification == "verified";
    any_unverified = any_unverified || e->verification == "unverified";
  }
  out.verification = any_unverified ? "unverified" : all_verified ? "verified" : "off";
  return out;
}

void AddCounts(const BoundsSummary& p, BoundsSummary& sum) {
  sum.sdp_jobs += p.sdp_jobs;
  sum.sdp_solves += p.sdp_solves;
  sum.jobs_from_cache += p.jobs_from_cache;
  sum.jobs_stopped_beyond_witness += p.jobs_stopped_beyond_witness;
  sum.jobs_settled_by_sign += p.jobs_settled_by_sign;
  sum.edge_witness_settled += p.edge_witness_settled;
  sum.edge_witness_solves += p.edge_witness_solves;
  sum.edge_witness_seconds += p.edge_witness_seconds;
  sum.moment_witness_jobs += p.moment_witness_jobs;
  sum.moment_witness_found += p.moment_witness_found;
  sum.moment_witness_seconds += p.moment_witness_seconds;
  sum.solve_seconds += p.solve_seconds;
  sum.verify_seconds += p.verify_seconds;
  sum.wall_seconds += p.wall_seconds;
  sum.largest_moments = std::max(sum.largest_moments, p.largest_moments);
  sum.largest_blocks = std::max(sum.largest_blocks, p.largest_blocks);
  sum.contraction_passes_run = std::max(sum.contraction_passes_run, p.contraction_passes_run);
  sum.refine_jobs += p.refine_jobs;
  sum.refine_tightened += p.refine_tightened;
  sum.endpoint_refine_jobs += p.endpoint_refine_jobs;
  sum.endpoint_refine_tightened += p.endpoint_refine_tightened;
  for (const auto& [source, n] : p.bound_sources) sum.bound_sources[source] += n;
  sum.clipped_to_box = sum.clipped_to_box || p.clipped_to_box;
}

// Orthant l over the pieces: empty when empty in every piece, failed when it failed in one, else solved.
OrthantReport CombinedOrthant(const std::vector<BoundsSummary>& pieces, std::size_t l) {
  OrthantReport r = pieces.front().orthants[l];
  bool all_empty = true, any_failed = false, all_verified = true, any_contracted = false;
  int order = 0;
  for (const auto& p : pieces) {
    const OrthantReport& o = p.orthants[l];
    const bool empty = o.status.rfind("empty", 0) == 0;
    all_empty = all_empty && empty;
    any_failed = any_failed || o.status.rfind("failed", 0) == 0;
    if (empty && o.certificate) {
      all_verified = all_verified && o.certificate->verified;
      any_contracted = any_contracted || o.certificate->contracted_box;
      order = std::max(order, o.certificate->order);
    } else {
      all_verified = false;
    }
  }
  r.certificate.reset();
  if (all_empty) {
    r.certificate = EmptinessCertificate{"pieces", order, any_contracted, all_verified};
    r.status = r.certificate->status();
  } else {
    r.status = any_failed ? "failed (conservative fallback)" : "solved";
  }
  return r;
}

}  // namespace

bool ValidBoxCuts(const std::vector<BoxCut>& cuts, const std::vector<std::string>& names, const ParameterBox& box,
                  std::string* error) {
  std::set<std::string> seen;
  for (const auto& cut : cuts) {
    const std::size_t k = IndexOf(names, cut.parameter);
    if (k >= names.size() || k >= box.size())
      return Fail(error, fmt::format("split: no parameter '{}'; the parameters are: {}", cut.parameter, fmt::join(names, ", ")));
    if (!seen.insert(cut.parameter).second)
      return Fail(error, fmt::format("split: '{}' is cut twice; give all its cut points in one entry, e.g. {}=V1,V2",
                                     cut.parameter, cut.parameter));
    if (cut.values.empty()) return Fail(error, fmt::format("split: no cut point for '{}'", cut.parameter));
    std::vector<double> sorted = cut.values;
    std::sort(sorted.begin(), sorted.end());
    for (std::size_t i = 0; i < sorted.size(); ++i) {
      const double v = sorted[i];
      if (!std::isfinite(v) || !(v > box[k].first && v < box[k].second))
        return Fail(error, fmt::format("split: the cut {} = {} is not strictly inside its prior box side [{}, {}]",
                                       cut.parameter, v, box[k].first, box[k].second));
      if (i > 0 && v == sorted[i - 1])
        return Fail(error, fmt::format("split: the cut {} = {} is given twice", cut.parameter, v));
    }
  }
  return true;
}

std::vector<ParameterBox> BoxPieces(const ParameterBox& box, const std::vector<BoxCut>& cuts,
                                    const std::vector<std::string>& names) {
  std::vector<ParameterBox> pieces = {box};
  for (const auto& cut : cuts) {
    const std::size_t k = IndexOf(names, cut.parameter);
    std::vector<ParameterBox> next;
    for (const auto& piece : pieces)
      for (const auto& slab : Slabs(piece[k], cut.values)) {
        next.push_back(piece);
        next.back()[k] = slab;
      }
    pieces = std::move(next);
  }
  return pieces;
}

BoundsSummary CombinePieces(const std::vector<BoundsSummary>& pieces, const ParameterBox& box) {
  if (pieces.empty()) throw std::logic_error("CombinePieces: no piece");
  const BoundsSummary& first = pieces.front();
  BoundsSummary out;
  out.order = first.order;
  out.horizon = first.horizon;
  out.solver = first.solver;
  out.solver_option = first.solver_option;
  out.relaxation = first.relaxation;
  out.executor = first.executor;
  out.parameter_names = first.parameter_names;
  out.box = box;
  out.orthants_total = first.orthants_total;
  std::vector<double> medians;
  for (const auto& p : pieces) {
    if (p.orthants.size() != first.orthants.size() || p.intervals.size() != first.intervals.size())
      throw std::logic_error("CombinePieces: the pieces are not runs of one problem");
    AddCounts(p, out);
    medians.push_back(p.median_solve_seconds);
    out.feasible_points.insert(out.feasible_points.end(), p.feasible_points.begin(), p.feasible_points.end());
    out.pieces.push_back(p.to_json());  // with its own "invalidated" and "prior_box"
  }
  std::sort(medians.begin(), medians.end());
  out.median_solve_seconds = medians[medians.size() / 2];
  for (std::size_t l = 0; l < first.orthants.size(); ++l) {
    out.orthants.push_back(CombinedOrthant(pieces, l));
    const std::string& s = out.orthants.back().status;
    if (s.rfind("empty", 0) == 0) ++out.orthants_empty;
    else if (s.rfind("failed", 0) == 0) ++out.orthants_failed;
    else ++out.orthants_solved;
  }
  std::vector<int> live;
  for (std::size_t i = 0; i < pieces.size(); ++i)
    if (!pieces[i].invalidated()) live.push_back(static_cast<int>(i));
  if (live.empty()) {  // every piece proven empty: no endpoint; the intervals keep their names
    out.intervals = first.intervals;
    return out;
  }
  for (std::size_t i = 0; i < first.intervals.size(); ++i) {
    ParameterInterval iv;
    iv.name = first.intervals[i].name;
    std::vector<const Endpoint*> lowers, uppers;
    for (int p : live) {
      const ParameterInterval& piv = pieces[p].intervals[i];
      lowers.push_back(&piv.lower);
      uppers.push_back(&piv.upper);
      if (piv.witnessed_lower) iv.witnessed_lower = std::min(iv.witnessed_lower.value_or(*piv.witnessed_lower), *piv.witnessed_lower);
      if (piv.witnessed_upper) iv.witnessed_upper = std::max(iv.witnessed_upper.value_or(*piv.witnessed_upper), *piv.witnessed_upper);
    }
    iv.lower = OutermostEndpoint(lowers, live, -1);
    iv.upper = OutermostEndpoint(uppers, live, +1);
    out.intervals.push_back(std::move(iv));
  }
  return out;
}

std::optional<UnwitnessedPart> LargestUnwitnessedPart(const BoundsSummary& summary) {
  std::optional<UnwitnessedPart> largest;
  if (summary.invalidated()) return largest;
  for (const auto& iv : summary.intervals) {
    const double width = iv.upper.value - iv.lower.value;
    if (!iv.witnessed_lower || !iv.witnessed_upper || !(width > 0)) continue;
    for (const bool below : {true, false}) {
      const UnwitnessedPart part{iv.name, below, below ? iv.lower.value : iv.upper.value,
                                 below ? *iv.witnessed_lower : *iv.witnessed_upper,
                                 (below ? *iv.witnessed_lower - iv.lower.value : iv.upper.value - *iv.witnessed_upper) /
                                     width};
      if (!largest || part.fraction > largest->fraction) largest = part;
    }
  }
  return largest;
}

BoundsSummary ComputeBoundsInPieces(const BoundsOptions& options, const HwOuterSet& set,
                                    const std::vector<BoxCut>& cuts,
                                    const std::function<void(const BoundsProgress&)>& progress) {
  if (cuts.empty()) return ComputeBounds(options, set, progress);
  std::string error;
  if (!ValidBoxCuts(cuts, set.layout().names, set.box(), &error)) throw InputError(error);
  const auto t0 = std::chrono::steady_clock::now();
  const std::vector<ParameterBox> boxes = BoxPieces(set.box(), cuts, set.layout().names);
  std::vector<BoundsSummary> pieces;
  for (std::size_t k = 0; k < boxes.size(); ++k) {
    auto piece_progress = [&](const BoundsProgress& p) {
      if (!progress) return;
      BoundsProgress q = p;
      q.phase = fmt::format("piece {} of {}: {}", k + 1, boxes.size(), p.phase);
      progress(q);
    };
    pieces.push_back(ComputeBounds(options, set.WithBox(boxes[k]), piece_progress));
  }
  // An MPI worker rank served one session per piece, as the coordinator ran them, and holds no result.
  if (pieces.front().worker_rank) return pieces.front();
  BoundsSummary combined = CombinePieces(pieces, set.box());
  combined.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return combined;
}

}  // namespace hw::relax
