#include "exact/exact_report.hpp"

#include <fmt/format.h>

namespace hw::exact {

bool TruthInside(const ExactBoundsSummary& summary, const std::vector<double>& truth) {
  if (truth.empty() || summary.invalidated) return true;
  for (std::size_t k = 0; k < summary.intervals.size() && k < truth.size(); ++k)
    if (!(summary.intervals[k].lower.value <= truth[k] && truth[k] <= summary.intervals[k].upper.value)) return false;
  return true;
}

std::string ExactReport(const ExactBoundsSummary& s, const ExactReportOptions& o) {
  std::string out;
  if (s.invalidated) {
    out += fmt::format("\nexact set D: EMPTY. Every box of the start box is proven empty ({} certificates): no "
                       "parameter explains the whole record within the noise bound under the assumptions below.\n",
                       s.certificates.size());
  } else {
    out += fmt::format("\nexact set D (one noise sequence for the whole record): guaranteed intervals\n");
    out += fmt::format("{:<8} {:>12} {:>12} {:>12} {:>12} {:>11}  {:>12} {:>12}{}\n", "param", "lower", "upper",
                       "inner lo", "inner hi", "outer/inner", o.outer_label + " lo", o.outer_label + " hi",
                       o.truth.empty() ? "" : "  truth");
    for (std::size_t k = 0; k < s.intervals.size(); ++k) {
      const auto& iv = s.intervals[k];
      std::string inner_lo = "-", inner_hi = "-", ratio = "-";
      if (iv.inner) {
        inner_lo = fmt::format("{:.6g}", iv.inner->first);
        inner_hi = fmt::format("{:.6g}", iv.inner->second);
        const double w = iv.inner->second - iv.inner->first;
        if (w > 0) ratio = fmt::format("{:.2f}", (iv.upper.value - iv.lower.value) / w);
      }
      std::string outer_lo = "-", outer_hi = "-";
      if (k < o.outer.size()) {
        outer_lo = fmt::format("{:.6g}", o.outer[k].first);
        outer_hi = fmt::format("{:.6g}", o.outer[k].second);
      }
      std::string truth;
      if (k < o.truth.size())
        truth = fmt::format("  {:.6g} {}", o.truth[k],
                            iv.lower.value <= o.truth[k] && o.truth[k] <= iv.upper.value ? "inside" : "OUTSIDE");
      const bool conservative =
          iv.lower.status != EndpointStatus::kGuaranteed || iv.upper.status != EndpointStatus::kGuaranteed;
      out += fmt::format("{:<8} {:>12.6g} {:>12.6g} {:>12} {:>12} {:>11}  {:>12} {:>12}{}{}\n", iv.name, iv.lower.value,
                         iv.upper.value, inner_lo, inner_hi, ratio, outer_lo, outer_hi, truth,
                         conservative ? "  (an end is the start box's edge)" : "");
    }
  }
  out += fmt::format("assumptions: {}; {}\n", o.model_class, MonotoneAssumptionText());
  if (!s.invalidated)
    out += fmt::format("assumption on the result: {} (smallest increase of p over a grid step {:.3g}, on [{:.4g}, {:.4g}])\n",
                       s.assumption.holds ? "holds for every alpha of the box" : "NOT shown for every alpha of the box",
                       s.assumption.smallest_increase, s.assumption.where_lo, s.assumption.where_hi);
  out += fmt::format("certificates: every pruned box and every bound from a safe LP bound (outward-rounded interval "
                     "arithmetic on the duals); {} LPs ({} did not end optimal and were kept or refined)\n",
                     s.lps, s.lp_failures);
  out += fmt::format("stage 2: {} levels, {} boxes tested, {} pruned, {} live; {} sweeps{}; LP {} x {} ({} nonzeros); {} jobs on {} "
                     "({} from the run directory); {:.1f} s (prune {:.1f}, inner hull {:.1f}, bound {:.1f})",
                     s.prune_levels, s.boxes_evaluated, s.boxes_pruned, s.boxes_live, s.sweeps, s.closing_pass ? " and a closing pass" : "", s.lp_rows, s.lp_cols,
                     s.lp_nonzeros, s.jobs, s.executor, s.jobs_from_cache, s.wall_seconds, s.prune_seconds,
                     s.inner_seconds, s.bound_seconds);
  if (o.stage1_seconds > 0) out += fmt::format("; stage 1 ({}) {:.1f} s", o.outer_label, o.stage1_seconds);
  out += "\n";
  return out;
}

}  // namespace hw::exact
