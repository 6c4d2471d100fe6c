#pragma once
// Bounds over a prior box cut into pieces: one level of branch and bound, at cut points the caller names.
//
// The pieces cover the box, so the hull of their intervals bounds D^ss(n) in the box as the whole-box run does.
// It is often much tighter: an orthant whose relaxation cannot exclude a far, empty part of its box in one piece
// can be proven empty there once that part is a piece of its own (README, "The relaxation gap at δ = 3": on
// seed 3 at 31 dB a cut at γ2 = 0 takes γ3's outer/inner half-width ratio from 1.86 to 1.006). A good cut lies
// where the certified feasible points of a parameter end and its outer interval goes on (the "witnessed" range
// of a first run).
#include <functional>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "relax/hw_outer_set.hpp"
#include "relax/set_membership.hpp"

namespace hw::relax {

using ParameterBox = std::vector<std::pair<double, double>>;

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

// ComputeBounds in each piece of set.box() (same options, run cache and executor; each piece resumes on its
// own), combined by CombinePieces. Progress phases start with "piece k of K: ". No cut: ComputeBounds itself.
BoundsSummary ComputeBoundsInPieces(const BoundsOptions& options, const HwOuterSet& set,
                                    const std::vector<BoxCut>& cuts,
                                    const std::function<void(const BoundsProgress&)>& progress = {});

}  // namespace hw::relax
