#include "dss/bounds_summary.hpp"

#include <fmt/format.h>

namespace hw::dss {

std::string EmptinessCertificate::status() const {
  if (kind == CertificateKind::kLinearProgram) return "empty (LP)";
  if (kind == CertificateKind::kPieces) return order > 0 ? fmt::format("empty in every piece (up to order {})", order) : "empty in every piece (LP)";
  return fmt::format("empty (order {}{}{})", order, contracted_box ? ", contracted box" : "",
                     kind == CertificateKind::kCrossedBounds ? ", bounds cross" : "");
}

std::string OrthantReport::status_text() const {
  return status == OrthantStatus::kEmpty && certificate ? certificate->status() : ToString(status);
}

nlohmann::json EmptinessCertificate::to_json() const {
  return {{"kind", ToString(kind)}, {"order", kind == CertificateKind::kLinearProgram ? nlohmann::json(nullptr) : nlohmann::json(order)},
          {"contracted_box", contracted_box}, {"verified", verified}};
}

bool BoundsSummary::invalidated() const {
  if (orthants_total == 0 || orthants_empty != orthants_total) return false;
  for (const auto& o : orthants)
    if (!o.empty()) return false;
  return true;
}

bool BoundsSummary::all_guaranteed() const {
  if (invalidated()) return true;  // every orthant proven empty: no endpoint to guarantee
  for (const auto& iv : intervals)
    for (const Endpoint* e : {&iv.lower, &iv.upper})
      // A floating-point bound that verification could not prove is not called guaranteed.
      if (e->status != EndpointStatus::kGuaranteed || e->verification == sdp::VerifyStatus::kUnverified) return false;
  return true;
}

nlohmann::json BoundsSummary::to_json() const {
  nlohmann::json j;
  j["order"] = order;
  j["horizon"] = horizon;
  j["solver"] = solver;
  j["solver_option"] = solver_option;
  j["relaxation"] = relaxation;
  j["executor"] = executor;
  nlohmann::json box_j = nlohmann::json::array();
  for (std::size_t i = 0; i < box.size(); ++i)
    box_j.push_back({{"parameter", parameter_names[i]}, {"lo", box[i].first}, {"hi", box[i].second}});
  j["prior_box"] = box_j;
  j["prior_box_note"] = "intervals are guaranteed for parameters inside this box (a prior assumption)";
  const bool none = invalidated();
  j["invalidated"] = none;
  if (none)
    j["verdict"] = "no parameter in the prior box explains the data within the noise bound: the model class "
                   "(orders, bases) or the noise bound is wrong (every orthant is proven empty; see `hwbounds diagnose`)";
  auto ep = [none](const Endpoint& e) {
    return nlohmann::json{{"value", none ? nlohmann::json(nullptr) : nlohmann::json(e.value)}, {"status", ToString(e.status)}, {"note", e.note}, {"orthant", e.orthant},
                          {"tight", e.tight}, {"verification", sdp::ToString(e.verification)}, {"correction", e.correction}};
  };
  auto witnessed = [](const ParameterInterval& iv) {
    if (!iv.witnessed_lower || !iv.witnessed_upper) return nlohmann::json(nullptr);
    return nlohmann::json{{"lower", *iv.witnessed_lower}, {"upper", *iv.witnessed_upper}};
  };
  for (const auto& iv : intervals)
    j["intervals"].push_back({{"parameter", iv.name}, {"lower", ep(iv.lower)}, {"upper", ep(iv.upper)},
                              {"half_width", none ? nlohmann::json(nullptr) : nlohmann::json(iv.half_width())},
                              {"witnessed", witnessed(iv)}});
  j["feasible_points"] = nlohmann::json::array();
  for (const auto& p : feasible_points) {
    nlohmann::json point;
    for (std::size_t i = 0; i < p.point.size() && i < parameter_names.size(); ++i) point[parameter_names[i]] = p.point[i];
    j["feasible_points"].push_back(
        {{"orthant", p.orthant}, {"point", point}, {"certified_min_slack", p.certified_min_slack}});
  }
  for (const auto& o : orthants)
    j["orthants"].push_back({{"index", o.index}, {"signs", o.signs}, {"status", o.status_text()},
                             {"certificate", o.certificate ? o.certificate->to_json() : nlohmann::json(nullptr)}});
  j["counts"] = {{"orthants_total", orthants_total}, {"orthants_proven_empty", orthants_empty},
                 {"orthants_solved", orthants_solved}, {"orthants_failed", orthants_failed},
                 {"sdp_jobs", sdp_jobs}, {"sdp_solves", sdp_solves}, {"jobs_from_cache", jobs_from_cache},
                 {"jobs_stopped_beyond_witness", jobs_stopped_beyond_witness},
                 {"jobs_settled_by_sign", jobs_settled_by_sign},
                 {"edge_witness_settled", edge_witness_settled}, {"edge_witness_solves", edge_witness_solves},
                 {"moment_witness_jobs", moment_witness_jobs}, {"moment_witness_found", moment_witness_found}};
  j["timing"] = {{"wall_seconds", wall_seconds}, {"median_solve_seconds", median_solve_seconds},
                 {"solve_seconds", solve_seconds}, {"verify_seconds", verify_seconds},
                 {"edge_witness_seconds", edge_witness_seconds}, {"moment_witness_seconds", moment_witness_seconds}};
  j["largest_sdp"] = {{"moments", largest_moments}, {"blocks", largest_blocks}};
  j["all_guaranteed"] = all_guaranteed();
  j["contraction_passes_run"] = contraction_passes_run;
  j["stopped_short_refined"] = {{"jobs", refine_jobs}, {"tightened", refine_tightened}};
  j["endpoints_refined"] = {{"jobs", endpoint_refine_jobs}, {"tightened", endpoint_refine_tightened}};
  j["row_reduction"] = row_reduction;
  j["bound_sources"] = ByName(bound_sources);
  j["clipped_to_prior_box"] = clipped_to_box;
  if (!pieces.empty()) j["pieces"] = pieces;
  if (!auto_split.is_null()) j["auto_split"] = auto_split;
  for (const auto& [l, b] : orthant_boxes) {
    nlohmann::json bj = nlohmann::json::array();
    for (std::size_t i = 0; i < b.size(); ++i)
      bj.push_back({{"parameter", parameter_names[i]}, {"lo", b[i].first}, {"hi", b[i].second}});
    j["contracted_boxes"].push_back({{"orthant", l}, {"box", bj}});
  }
  return j;
}

}  // namespace hw::dss
