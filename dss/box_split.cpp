#include "dss/box_split.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <set>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "core/input_error.hpp"
#include "dss/bounds_options.hpp"  // ValidAutoSplitRounds, with the other settings' checks

namespace hw::dss {
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
    if (e->status != EndpointStatus::kGuaranteed) out.status = EndpointStatus::kConservative;
    out.tight = out.tight && e->tight;
    out.correction = std::max(out.correction, e->correction);
    all_verified = all_verified && e->verification == sdp::VerifyStatus::kVerified;
    any_unverified = any_unverified || e->verification == sdp::VerifyStatus::kUnverified;
  }
  out.verification = any_unverified ? sdp::VerifyStatus::kUnverified
                     : all_verified ? sdp::VerifyStatus::kVerified
                                    : sdp::VerifyStatus::kNotRun;
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
    const bool empty = o.empty();
    all_empty = all_empty && empty;
    any_failed = any_failed || o.status == OrthantStatus::kFailed;
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
    r.certificate = EmptinessCertificate{CertificateKind::kPieces, order, any_contracted, all_verified};
    r.status = OrthantStatus::kEmpty;
  } else {
    r.status = any_failed ? OrthantStatus::kFailed : OrthantStatus::kSolved;
  }
  return r;
}

// `into`'s witnessed range widened to cover `from`'s (both ranges of certified points of one parameter).
void WidenWitnessedRange(ParameterInterval& into, const ParameterInterval& from) {
  if (from.witnessed_lower) into.witnessed_lower = std::min(into.witnessed_lower.value_or(*from.witnessed_lower), *from.witnessed_lower);
  if (from.witnessed_upper) into.witnessed_upper = std::max(into.witnessed_upper.value_or(*from.witnessed_upper), *from.witnessed_upper);
}

// A round of ComputeBoundsWithAutoSplit as JSON: its box, the cut it added (none for the first run) and what it
// gave.
nlohmann::json RoundJson(int round, const ParameterBox& box, const std::optional<UnwitnessedPart>& part, double cut,
                         const BoundsSummary& s) {
  nlohmann::json j;
  j["round"] = round;
  for (std::size_t i = 0; i < box.size(); ++i)
    j["box"].push_back({{"parameter", s.parameter_names[i]}, {"lo", box[i].first}, {"hi", box[i].second}});
  j["cut"] = part ? nlohmann::json{{"parameter", part->parameter}, {"value", cut}, {"unwitnessed_fraction", part->fraction}}
                  : nlohmann::json(nullptr);
  j["pieces"] = std::max<std::size_t>(1, s.pieces.size());
  j["invalidated"] = s.invalidated();
  j["intervals"] = nlohmann::json::array();
  if (!s.invalidated())
    for (const auto& iv : s.intervals)
      j["intervals"].push_back({{"parameter", iv.name}, {"lower", iv.lower.value}, {"upper", iv.upper.value}});
  j["sdp_solves"] = s.sdp_solves;
  j["wall_seconds"] = s.wall_seconds;
  return j;
}

// The witnessed ranges and feasible points of `earlier` carried into `later` (both bound D^ss(n) in one box, and
// a certified point stays certified).
void KeepWitnesses(const BoundsSummary& earlier, BoundsSummary& later) {
  later.feasible_points.insert(later.feasible_points.begin(), earlier.feasible_points.begin(),
                               earlier.feasible_points.end());
  if (earlier.invalidated() || later.invalidated()) return;
  for (auto& iv : later.intervals)
    for (const auto& e : earlier.intervals)
      if (e.name == iv.name) WidenWitnessedRange(iv, e);
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
    const OrthantStatus s = out.orthants.back().status;
    if (s == OrthantStatus::kEmpty) ++out.orthants_empty;
    else if (s == OrthantStatus::kFailed) ++out.orthants_failed;
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
      WidenWitnessedRange(iv, piv);
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

ParameterBox ProvenBox(const BoundsSummary& summary, const ParameterBox& box) {
  ParameterBox proven = box;
  if (summary.invalidated()) return proven;
  for (const auto& iv : summary.intervals) {
    const std::size_t k = IndexOf(summary.parameter_names, iv.name);
    if (k >= proven.size()) continue;
    auto side = proven[k];
    if (iv.lower.verification == sdp::VerifyStatus::kVerified) side.first = std::max(side.first, iv.lower.value);
    if (iv.upper.verification == sdp::VerifyStatus::kVerified) side.second = std::min(side.second, iv.upper.value);
    if (side.first < side.second) proven[k] = side;  // a point interval keeps its box side: no empty box side
  }
  return proven;
}

bool AutoSplitOptions::IsValid(std::string* error) const {
  if (!ValidAutoSplitRounds(rounds, "", error)) return false;
  if (!(min_fraction > 0 && min_fraction < 1))
    return Fail(error, fmt::format("auto split: min_fraction {} is not in (0, 1)", min_fraction));
  if (!(margin >= 0 && margin < min_fraction))
    return Fail(error, fmt::format("auto split: margin {} is not in [0, min_fraction = {})", margin, min_fraction));
  return true;
}

double CutBeyondWitness(const UnwitnessedPart& part, const BoundsSummary& summary, double margin) {
  for (const auto& iv : summary.intervals)
    if (iv.name == part.parameter) {
      const double step = margin * (iv.upper.value - iv.lower.value);
      return part.below ? part.witnessed - step : part.witnessed + step;
    }
  throw std::logic_error("CutBeyondWitness: no interval of " + part.parameter);
}

std::vector<BoxCut> WithCut(std::vector<BoxCut> cuts, const std::string& parameter, double value,
                            const ParameterBox& box, const std::vector<std::string>& names) {
  auto it = std::find_if(cuts.begin(), cuts.end(), [&](const BoxCut& c) { return c.parameter == parameter; });
  if (it == cuts.end()) {
    cuts.push_back({parameter, {}});
    it = cuts.end() - 1;
  }
  if (std::find(it->values.begin(), it->values.end(), value) == it->values.end()) it->values.push_back(value);
  for (auto& cut : cuts) {
    const auto side = box[IndexOf(names, cut.parameter)];
    std::erase_if(cut.values, [&](double v) { return !(v > side.first && v < side.second); });
  }
  std::erase_if(cuts, [](const BoxCut& c) { return c.values.empty(); });
  return cuts;
}

BoundsSummary BoundsInPieces(const BoundsRun& run, const HwOuterSet& set, const std::vector<BoxCut>& cuts,
                             const ProgressSink& progress) {
  if (cuts.empty()) return run(set, progress);
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
    pieces.push_back(run(set.WithBox(boxes[k]), piece_progress));
  }
  // An MPI worker rank served one session per piece, as the coordinator ran them, and holds no result.
  if (pieces.front().worker_rank) return pieces.front();
  BoundsSummary combined = CombinePieces(pieces, set.box());
  combined.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return combined;
}

namespace {

// The round after `result` (run in `box` at `cuts`): its cut, box and cuts, or why there is none.
struct NextRound {
  std::optional<UnwitnessedPart> part;
  double cut = 0.0;
  ParameterBox box;
  std::vector<BoxCut> cuts;
  std::string stop;  // non-empty: no further round
};

NextRound PlanNextRound(const BoundsSummary& result, const ParameterBox& box, const std::vector<BoxCut>& cuts,
                        const AutoSplitOptions& auto_split, const std::vector<std::string>& names) {
  NextRound next;
  if (result.invalidated()) {
    next.stop = "every orthant is proven empty";
    return next;
  }
  next.part = LargestUnwitnessedPart(result);
  if (!next.part) {
    next.stop = "no interval has a range of certified feasible points to cut beyond";
    return next;
  }
  if (next.part->fraction < auto_split.min_fraction) {
    next.stop = fmt::format("the largest unwitnessed part ({}, {:.1f}% of its interval) is under {:.0f}%",
                            next.part->parameter, 100 * next.part->fraction, 100 * auto_split.min_fraction);
    return next;
  }
  next.cut = CutBeyondWitness(*next.part, result, auto_split.margin);
  next.box = ProvenBox(result, box);
  next.cuts = WithCut(cuts, next.part->parameter, next.cut, next.box, names);
  const auto same = [](const BoxCut& a, const BoxCut& b) { return a.parameter == b.parameter && a.values == b.values; };
  if (next.box == box && std::equal(next.cuts.begin(), next.cuts.end(), cuts.begin(), cuts.end(), same))
    next.stop = fmt::format("the next cut ({} = {:.6g}) is in place and the box did not shrink",
                            next.part->parameter, next.cut);
  return next;
}

}  // namespace

BoundsSummary BoundsWithAutoSplit(const BoundsRun& run, const std::string& executor, const HwOuterSet& set,
                                  const std::vector<BoxCut>& cuts, const AutoSplitOptions& auto_split,
                                  const ProgressSink& progress) {
  std::string error;
  if (!auto_split.IsValid(&error)) throw InputError(error);
  if (!ValidAutoSplitRounds(auto_split.rounds, executor, &error)) throw InputError(error);
  if (auto_split.rounds == 0) return BoundsInPieces(run, set, cuts, progress);
  auto round_progress = [&](int round) {
    return [&progress, round](const BoundsProgress& p) {
      if (!progress) return;
      BoundsProgress q = p;
      if (round > 0) q.phase = fmt::format("auto split round {}: {}", round, p.phase);
      progress(q);
    };
  };
  ParameterBox box = set.box();
  std::vector<BoxCut> round_cuts = cuts;
  BoundsSummary result = BoundsInPieces(run, set, round_cuts, round_progress(0));
  nlohmann::json rounds = nlohmann::json::array({RoundJson(0, box, std::nullopt, 0.0, result)});
  std::string stopped = fmt::format("the {} round(s) asked for ran", auto_split.rounds);
  std::vector<BoundsSummary> earlier;
  for (int round = 1; round <= auto_split.rounds; ++round) {
    NextRound plan = PlanNextRound(result, box, round_cuts, auto_split, set.layout().names);
    if (!plan.stop.empty()) {
      stopped = plan.stop;
      break;
    }
    BoundsSummary next = BoundsInPieces(run, set.WithBox(plan.box), plan.cuts, round_progress(round));
    KeepWitnesses(result, next);
    rounds.push_back(RoundJson(round, plan.box, plan.part, plan.cut, next));
    earlier.push_back(std::move(result));
    result = std::move(next);
    box = std::move(plan.box);
    round_cuts = std::move(plan.cuts);
  }
  for (const auto& e : earlier) AddCounts(e, result);
  result.box = set.box();
  result.auto_split = {{"rounds", std::move(rounds)}, {"stopped", stopped}};
  return result;
}

}  // namespace hw::dss
