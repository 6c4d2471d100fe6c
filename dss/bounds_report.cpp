#include "dss/bounds_report.hpp"

#include <algorithm>
#include <iterator>
#include <map>

#include <fmt/format.h>

#include "dss/box_split.hpp"

namespace hw::dss {
namespace {

// The interval table, with each true value given inside or OUTSIDE its interval.
void AppendIntervals(std::string& out, const BoundsSummary& summary, const std::vector<double>& truth) {
  const auto& names = summary.parameter_names;
  fmt::format_to(std::back_inserter(out), "\n{:<10} {:>12} {:>12} {:>11}  {:<10} {:>19}  {:<25}  {}\n", "parameter", "lower", "upper", "half-width",
             "verified", "correction lo/up", "feasible points reach", "status");
  for (const auto& iv : summary.intervals) {
    const std::size_t k = std::find(names.begin(), names.end(), iv.name) - names.begin();
    const bool both_guaranteed =
        iv.lower.status == EndpointStatus::kGuaranteed && iv.upper.status == EndpointStatus::kGuaranteed;
    std::string status = both_guaranteed ? ToString(EndpointStatus::kGuaranteed)
                                         : fmt::format("lower {}, upper {}", ToString(iv.lower.status),
                                                       ToString(iv.upper.status));
    if (!truth.empty()) {
      const bool in = iv.lower.value <= truth[k] && truth[k] <= iv.upper.value;
      status += fmt::format("  truth {:.6g} {}", truth[k], in ? "inside" : "OUTSIDE");
    }
    const std::string verified = iv.lower.verification == iv.upper.verification
                                     ? sdp::ToString(iv.lower.verification)
                                     : sdp::ToString(iv.lower.verification) + "/" + sdp::ToString(iv.upper.verification);
    // The inner side: certified points of the set reach this range, so the exact interval lies between the two.
    const std::string reached = iv.witnessed_lower && iv.witnessed_upper
                                    ? fmt::format("[{:.6f}, {:.6f}]", *iv.witnessed_lower, *iv.witnessed_upper)
                                    : "-";
    fmt::format_to(std::back_inserter(out), "{:<10} {:>12.6f} {:>12.6f} {:>11.6f}  {:<10} {:>9.1e}/{:<9.1e}  {:<25}  {}\n", iv.name, iv.lower.value,
               iv.upper.value, iv.half_width(), verified, iv.lower.correction, iv.upper.correction, reached, status);
    for (const auto* ep : {&iv.lower, &iv.upper})
      if (!ep->note.empty()) fmt::format_to(std::back_inserter(out), "           note: {}\n", ep->note);
  }
}

// How one orthant was proven empty, for a person: "LP screen, verified in interval arithmetic".
std::string CertificateText(const EmptinessCertificate& c) {
  std::string how;
  switch (c.kind) {
    case CertificateKind::kLinearProgram: how = "LP screen infeasible"; break;
    case CertificateKind::kRelaxation: how = fmt::format("order {} relaxation infeasible", c.order); break;
    case CertificateKind::kPieces: how = "proven empty in every piece of the split box"; break;
    case CertificateKind::kCrossedBounds: how = fmt::format("order {} bounds cross", c.order); break;
  }
  return fmt::format("{}{}, {}", how, c.contracted_box ? " in the contracted box" : "",
                     c.verified ? "verified in interval arithmetic" : "the solver's floating-point certificate (unverified)");
}

// The verdict of an empty feasible set: what it means, which certificates prove it, where to look next.
void AppendInvalidation(std::string& out, const BoundsSummary& summary, const BoundsReportOptions& o) {
  fmt::format_to(std::back_inserter(out), "\nVERDICT: model invalidated. No parameter in the prior box explains the data within the noise bound: "
             "the model class ({}) or the noise bound is wrong.\n",
             o.model_class.empty() ? fmt::format("horizon {}", summary.horizon) : o.model_class);
  std::map<std::string, int> by_certificate;
  int verified = 0;
  for (const auto& r : summary.orthants) {
    ++by_certificate[r.status_text()];
    verified += r.certificate && r.certificate->verified ? 1 : 0;
  }
  std::string counts;
  for (const auto& [kind, n] : by_certificate) counts += fmt::format("{}{} {}", counts.empty() ? "" : ", ", n, kind);
  fmt::format_to(std::back_inserter(out), "certificates: all {} sign orthants are proven empty ({}); {} of them verified in interval arithmetic{}:\n",
             summary.orthants_total, counts, verified, o.verify ? "" : " (verification off)");
  for (const auto& r : summary.orthants)
    fmt::format_to(std::back_inserter(out), "  orthant {:>3} ({}): {}\n", r.index, r.signs, r.certificate ? CertificateText(*r.certificate) : r.status_text());
  fmt::format_to(std::back_inserter(out), "next: `hwbounds diagnose --data REC --validate REC2 --fit hw:NA,NB,PIN,POUT` looks for what the model "
             "leaves out (docs/diagnose.md); a larger noise bound, other bases or orders, or a wider --box change the "
             "question.\n");
}

// One line per piece of a split box: its box side(s) that differ from the prior box, and what it gave.
void AppendPieces(std::string& out, const BoundsSummary& summary) {
  if (summary.pieces.empty()) return;
  fmt::format_to(std::back_inserter(out), "\nthe prior box split into {} pieces; the intervals above are the hull over the pieces:\n",
             summary.pieces.size());
  for (std::size_t k = 0; k < summary.pieces.size(); ++k) {
    const auto& piece = summary.pieces[k];
    std::string sides;
    const auto& box = piece.at("prior_box");
    for (std::size_t i = 0; i < box.size() && i < summary.box.size(); ++i)
      if (box[i].at("lo").get<double>() != summary.box[i].first || box[i].at("hi").get<double>() != summary.box[i].second)
        sides += fmt::format("{}{} in [{:.6g}, {:.6g}]", sides.empty() ? "" : ", ", box[i].at("parameter").get<std::string>(),
                             box[i].at("lo").get<double>(), box[i].at("hi").get<double>());
    std::string result;
    if (piece.at("invalidated").get<bool>()) {
      result = "every orthant proven empty";
    } else {
      for (const auto& iv : piece.at("intervals"))
        result += fmt::format("{}{} [{:.6f}, {:.6f}]", result.empty() ? "" : ", ", iv.at("parameter").get<std::string>(),
                              iv.at("lower").at("value").get<double>(), iv.at("upper").at("value").get<double>());
    }
    fmt::format_to(std::back_inserter(out), "  piece {} ({}): {}; wall {:.1f} s\n", k + 1, sides, result,
               piece.at("timing").at("wall_seconds").get<double>());
  }
}

// One line per automatic round: the cut it added, the box it ran in (the sides the earlier rounds proved), and
// what it gave.
void AppendAutoSplitRounds(std::string& out, const BoundsSummary& summary) {
  if (summary.auto_split.is_null()) return;
  const auto& rounds = summary.auto_split.at("rounds");
  fmt::format_to(std::back_inserter(out), "\nautomatic cuts: {} round(s) after the first run ({}); each bounds D^ss(n) in the prior box, the "
             "last one's intervals are those above:\n",
             rounds.size() - 1, summary.auto_split.at("stopped").get<std::string>());
  for (const auto& round : rounds) {
    const auto& cut = round.at("cut");
    std::string what = cut.is_null() ? std::string("first run")
                                     : fmt::format("cut {} = {:.6g} ({:.0f}% of its interval unwitnessed)",
                                                   cut.at("parameter").get<std::string>(), cut.at("value").get<double>(),
                                                   100 * cut.at("unwitnessed_fraction").get<double>());
    std::string intervals;
    for (const auto& iv : round.at("intervals"))
      intervals += fmt::format("{}{} [{:.6f}, {:.6f}]", intervals.empty() ? "" : ", ",
                               iv.at("parameter").get<std::string>(), iv.at("lower").get<double>(),
                               iv.at("upper").get<double>());
    fmt::format_to(std::back_inserter(out), "  round {} ({}, {} piece(s)): {}; wall {:.1f} s\n", round.at("round").get<int>(), what,
               round.at("pieces").get<std::size_t>(),
               round.at("invalidated").get<bool>() ? std::string("every orthant proven empty") : intervals,
               round.at("wall_seconds").get<double>());
  }
}

// Where the relaxation may overestimate most: the largest part of an interval no certified point reaches, from
// 10 % of its width on, with the cut that bounds that part on its own.
void AppendUnwitnessedPart(std::string& out, const BoundsSummary& summary) {
  const auto part = LargestUnwitnessedPart(summary);
  if (!part || part->fraction < 0.1) return;
  fmt::format_to(std::back_inserter(out), "\nlargest unwitnessed part: no certified feasible point has {} in {} ({:.0f}% of its interval); the "
             "relaxation may overestimate there. A cut just {} {:.6g} (--split {}=VALUE, or --auto-split 1 to place it) "
             "bounds that part on its own and may prove it empty (docs/setmembership.md, \"Box split\").\n",
             part->parameter,
             part->below ? fmt::format("[{:.6g}, {:.6g})", part->bound, part->witnessed)
                         : fmt::format("({:.6g}, {:.6g}]", part->witnessed, part->bound),
             100 * part->fraction, part->below ? "below" : "above", part->witnessed, part->parameter);
}

// The prior box, contracted boxes, relaxation, counts and times of the run, row reduction, bound sources.
void AppendRunSummary(std::string& out, const BoundsSummary& summary, bool verify) {
  const auto& names = summary.parameter_names;
  fmt::format_to(std::back_inserter(out), "\nprior box (assumption): ");
  for (std::size_t i = 0; i < names.size(); ++i)
    fmt::format_to(std::back_inserter(out), "{}{} in [{}, {}]", i ? ", " : "", names[i], summary.box[i].first, summary.box[i].second);
  for (const auto& [l, b] : summary.orthant_boxes) {
    fmt::format_to(std::back_inserter(out), "\ncontracted box of orthant {} (proven to hold its points of D^ss(n) in the prior box): ", l);
    for (std::size_t i = 0; i < names.size(); ++i)
      fmt::format_to(std::back_inserter(out), "{}{} in [{:.6g}, {:.6g}]", i ? ", " : "", names[i], b[i].first, b[i].second);
  }
  fmt::format_to(std::back_inserter(out), "\nrelaxation: {}", summary.relaxation);
  fmt::format_to(std::back_inserter(out), "\northants: {} total, {} proven empty, {} solved, {} failed; {} relaxation jobs ({} SDP solves, "
             "{} from cache), largest SDP {} moments / {} blocks, median solve {:.2f} s, wall {:.1f} s\n",
             summary.orthants_total, summary.orthants_empty, summary.orthants_solved, summary.orthants_failed,
             summary.sdp_jobs, summary.sdp_solves, summary.jobs_from_cache, summary.largest_moments,
             summary.largest_blocks, summary.median_solve_seconds, summary.wall_seconds);
  if (summary.edge_witness_solves > 0)
    fmt::format_to(std::back_inserter(out), "feasible points at the box edges: {} endpoint(s) settled without an SDP ({} local solves, {:.1f} s)\n",
               summary.edge_witness_settled, summary.edge_witness_solves, summary.edge_witness_seconds);
  if (summary.moment_witness_jobs > 0)
    fmt::format_to(std::back_inserter(out), "feasible points from the relaxations' moments: {} of {} local searches certified ({:.1f} s)\n",
               summary.moment_witness_found, summary.moment_witness_jobs, summary.moment_witness_seconds);
  if (summary.jobs_stopped_beyond_witness > 0)
    fmt::format_to(std::back_inserter(out), "{} relaxation job(s) ended early: their bound passed a certified feasible point's value, so further "
               "rounds could not move the endpoint\n", summary.jobs_stopped_beyond_witness);
  if (summary.refine_jobs > 0)
    fmt::format_to(std::back_inserter(out), "{} endpoint job(s) solved again in a contracted box after a solve stopped short; {} bound(s) "
               "tightened\n", summary.refine_jobs, summary.refine_tightened);
  if (summary.endpoint_refine_jobs > 0)
    fmt::format_to(std::back_inserter(out), "{} endpoint job(s) solved again in the box of the full pass's own bounds; {} bound(s) tightened\n",
               summary.endpoint_refine_jobs, summary.endpoint_refine_tightened);
  if (summary.jobs_settled_by_sign > 0)
    fmt::format_to(std::back_inserter(out), "{} relaxation job(s) not run: the orthant's sign constraints already bound them at or beyond a "
               "certified feasible point's value\n", summary.jobs_settled_by_sign);
  std::string reductions;  // one line for every live orthant: "orthant 48: step 1: 213 of 596, ...; orthant 49: ..."
  for (const auto& r : summary.row_reduction) {
    std::string steps;
    for (const auto& c : r.at("per_step"))
      if (c.contains("error"))
        steps += fmt::format("{}step {}: reduction failed ({}), every row of the orthant kept", steps.empty() ? "" : ", ",
                             c.value("step", 0), c.at("error").get<std::string>());
      else if (c.contains("step"))
        steps += fmt::format("{}step {}: {} of {}{}", steps.empty() ? "" : ", ", c.at("step").get<int>(),
                             c.at("kept").get<int>(), c.at("rows").get<int>(),
                             c.value("iteration_limited", 0) > 0
                                 ? fmt::format(" ({} kept after their LP hit the simplex iteration limit)",
                                               c.at("iteration_limited").get<int>())
                                 : std::string());
    reductions += fmt::format("{}orthant {}: {}", reductions.empty() ? "" : "; ", r.at("orthant").get<int>(), steps);
  }
  if (!reductions.empty()) fmt::format_to(std::back_inserter(out), "exact row reduction, data rows kept: {}\n", reductions);
  if (!summary.bound_sources.empty()) {
    std::string sources;
    for (const auto& [what, count] : ByName(summary.bound_sources))
      sources += fmt::format("{}{} {}", sources.empty() ? "" : ", ", count, what);
    fmt::format_to(std::back_inserter(out), "orthant bounds entering the endpoints: {}\n", sources);
  }
  if (summary.clipped_to_box) fmt::format_to(std::back_inserter(out), "note: endpoints beyond the prior box are intersected with it\n");
  if (verify)
    fmt::format_to(std::back_inserter(out), "verification: {:.2f} s for {:.2f} s of SDP solves ({:.1f}%)\n", summary.verify_seconds,
               summary.solve_seconds,
               summary.solve_seconds > 0 ? 100 * summary.verify_seconds / summary.solve_seconds : 0.0);
}

// Endpoints that are fallbacks or rest on unverified floating-point bounds.
void AppendWarnings(std::string& out, const BoundsSummary& summary, bool verify) {
  if (!summary.all_guaranteed())
    fmt::format_to(std::back_inserter(out), "WARNING: some endpoints are conservative fallbacks (still valid bounds) or floating-point bounds that "
               "verification could not prove (see notes and the verified column).\n");
  if (!verify) return;
  for (const auto& iv : summary.intervals)
    for (const auto* ep : {&iv.lower, &iv.upper})
      if (ep->verification == sdp::VerifyStatus::kUnverified) {
        fmt::format_to(std::back_inserter(out), "WARNING: {} has an endpoint that rests on an unverified floating-point bound (see notes).\n",
                   iv.name);
        break;
      }
}

}  // namespace

bool TruthCovered(const BoundsSummary& summary, const std::vector<double>& truth) {
  if (truth.empty()) return true;
  const auto& names = summary.parameter_names;
  for (const auto& iv : summary.intervals) {
    const std::size_t k = std::find(names.begin(), names.end(), iv.name) - names.begin();
    if (k >= truth.size() || !(iv.lower.value <= truth[k] && truth[k] <= iv.upper.value)) return false;
  }
  return true;
}

std::string BriefReport(const BoundsSummary& summary, const BoundsReportOptions& options) {
  std::string out;
  if (summary.invalidated()) {
    AppendInvalidation(out, summary, options);
    return out;
  }
  AppendIntervals(out, summary, options.truth);
  AppendWarnings(out, summary, options.verify);
  return out;
}

std::string FullReport(const BoundsSummary& summary, const BoundsReportOptions& options) {
  std::string out;
  const bool invalidated = summary.invalidated();
  if (invalidated) AppendInvalidation(out, summary, options);
  else AppendIntervals(out, summary, options.truth);
  AppendPieces(out, summary);
  AppendAutoSplitRounds(out, summary);
  AppendRunSummary(out, summary, options.verify);
  if (!invalidated) AppendWarnings(out, summary, options.verify);
  AppendUnwitnessedPart(out, summary);
  return out;
}

}  // namespace hw::dss
