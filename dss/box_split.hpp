#pragma once
// Bounds over a prior box cut into pieces: one level of branch and bound, at cut points the caller names.
//
// The pieces cover the box, so the hull of their intervals bounds D^ss(n) in the box as the whole-box run does.
// It is often much tighter: an orthant whose relaxation cannot exclude a far, empty part of its box in one piece
// can be proven empty there once that part is a piece of its own (docs/cerone_tables.md, "The relaxation gap at δ = 3": on
// seed 3 at 31 dB a cut at γ2 = 0 takes γ3's outer/inner half-width ratio from 1.86 to 1.006). A good cut lies
// where the certified feasible points of a parameter end and its outer interval goes on (the "witnessed" range
// of a first run).
#include <functional>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "dss/bounds_summary.hpp"
#include "dss/hw_outer_set.hpp"

namespace hw::dss {


// Cut points of one parameter: the box side of `parameter` splits at each of `values`.
struct BoxCut {
  std::string parameter;
  std::vector<double> values;
};

// Each parameter is cut in at most one entry, at distinct values strictly inside its side of `box`.
bool ValidBoxCuts(const std::vector<BoxCut>& cuts, const std::vector<std::string>& names, const ParameterBox& box,
                  std::string* error);

// The pieces of `box` (every combination of one slab per cut parameter), the first cut's slabs varying slowest.
// No cut: the box itself.
std::vector<ParameterBox> BoxPieces(const ParameterBox& box, const std::vector<BoxCut>& cuts,
                                    const std::vector<std::string>& names);

// The bounds over the union of the pieces from the pieces' own summaries (same data, model class, options):
// every endpoint is the outermost over the pieces not proven empty, "guaranteed" only when each of them is and
// "verified" only when each of them is; an orthant is empty when it is empty in every piece (certificate kind
// "pieces", verified when each piece's certificate is). Counts and times are sums, the median solve time the
// median of the pieces' medians; `box` is the union's box. Each piece's own JSON is kept in `pieces`.
BoundsSummary CombinePieces(const std::vector<BoundsSummary>& pieces, const ParameterBox& box);

// The side of an interval with the largest part that no certified feasible point reaches: [lower, witnessed_lower)
// or (witnessed_upper, upper], as a fraction of the interval's width. Where a relaxation overestimates most, a cut
// of the box just outside the witnessed value often lets it prove that part empty. Absent when no interval has a
// witnessed range or a positive width.
struct UnwitnessedPart {
  std::string parameter;
  bool below = true;        // the part lies below the witnessed range (else above it)
  double bound = 0.0;       // the interval's endpoint on that side
  double witnessed = 0.0;   // the witnessed range's end on that side
  double fraction = 0.0;    // |witnessed - bound| / (upper - lower)
};
std::optional<UnwitnessedPart> LargestUnwitnessedPart(const BoundsSummary& summary);

// The box a result proves to hold every point of D^ss(n) in `box`: each side of a computed interval whose endpoint
// is verified in interval arithmetic (any other side stays as in `box`).
ParameterBox ProvenBox(const BoundsSummary& summary, const ParameterBox& box);

// Automatic cuts (ComputeBoundsWithAutoSplit): after the run, up to `rounds` times, shrink the box to the
// proven intervals and cut off the largest unwitnessed part just beyond its last certified feasible point.
struct AutoSplitOptions {
  int rounds = 0;              // 0: no automatic cut
  double min_fraction = 0.1;   // a part under this share of its interval is not cut off (the CLI's hint threshold)
  double margin = 0.02;        // the cut lies this share of the interval's width beyond the witnessed value, so
                               // the cut-off piece holds no certified point and can be proven empty
  bool IsValid(std::string* error) const;
};
// (Its rounds' check, ValidAutoSplitRounds, is with the other settings' checks in dss/bounds_options.hpp.)

// The cut that bounds `part` on its own: `margin` x the interval's width beyond its witnessed end.
double CutBeyondWitness(const UnwitnessedPart& part, const BoundsSummary& summary, double margin);

// `cuts` with `value` added to the cut points of `parameter`, dropping every cut point that is not strictly inside
// `box` (a shrunk box can leave an earlier cut outside). Unchanged when `value` is already a cut point.
std::vector<BoxCut> WithCut(std::vector<BoxCut> cuts, const std::string& parameter, double value,
                            const ParameterBox& box, const std::vector<std::string>& names);

// One run of the bound engine over `set` (ComputeBounds with the caller's options, dss/set_membership.hpp): the
// runs below call it once per piece, so that this file needs nothing of the engine but its results.
using ProgressSink = std::function<void(const BoundsProgress&)>;
using BoundsRun = std::function<BoundsSummary(const HwOuterSet& set, const ProgressSink& progress)>;

// `run` in each piece of set.box() (same options, run cache and executor; each piece resumes on its own), combined
// by CombinePieces. Progress phases start with "piece k of K: ". No cut: `run` over set itself.
BoundsSummary BoundsInPieces(const BoundsRun& run, const HwOuterSet& set, const std::vector<BoxCut>& cuts,
                             const ProgressSink& progress);

// BoundsInPieces, then AutoSplitOptions::rounds rounds, each a run over the pieces of ProvenBox(last result) cut at
// the previous cuts and at CutBeyondWitness(LargestUnwitnessedPart); the rounds stop early when no part reaches
// min_fraction or its cut is already there. Each round bounds D^ss(n) in set.box(), so its intervals are valid and
// lie inside the previous round's. The result is the last round's, with set.box() as its box, every round's
// feasible points and witnessed ranges, counts and times summed over the rounds, and each round's box, cut and
// intervals in `auto_split`. Not under an MPI executor (`executor` names the run's; its worker ranks cannot follow
// the coordinator's cuts).
BoundsSummary BoundsWithAutoSplit(const BoundsRun& run, const std::string& executor, const HwOuterSet& set,
                                  const std::vector<BoxCut>& cuts, const AutoSplitOptions& auto_split,
                                  const ProgressSink& progress);

}  // namespace hw::dss
