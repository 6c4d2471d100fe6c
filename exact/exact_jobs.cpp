#include "exact/exact_jobs.hpp"

#include <cstdint>
#include <stdexcept>

#include <fmt/format.h>

namespace hw::exact {
namespace {

// The two kinds of job, as the spec's "kind" names them.
enum class JobKind { kEmptiness, kObjective };
constexpr const char* kEmptinessKind = "empty";
constexpr const char* kObjectiveKind = "objective";

JobKind KindOf(const nlohmann::json& spec) {
  const std::string kind = spec.at("kind").get<std::string>();
  if (kind == kEmptinessKind) return JobKind::kEmptiness;
  if (kind == kObjectiveKind) return JobKind::kObjective;
  throw std::invalid_argument("exact job: unknown kind '" + kind + "'");
}

}  // namespace

std::string EncodeBasis(const LpBasis& basis) {
  static const char* hex = "0123456789abcdef";
  std::string s;
  s.reserve(2 * basis.status.size());
  for (std::uint8_t b : basis.status) {
    s.push_back(hex[b >> 4]);
    s.push_back(hex[b & 15]);
  }
  return s;
}

LpBasis DecodeBasis(const std::string& text) {
  auto nibble = [](char c) -> int {
    if (c >= '0' && c <= '9') return c - '0';
    if (c >= 'a' && c <= 'f') return c - 'a' + 10;
    throw std::invalid_argument("basis: not a hex digit");
  };
  LpBasis b;
  if (text.size() % 2) throw std::invalid_argument("basis: odd length");
  for (std::size_t i = 0; i < text.size(); i += 2)
    b.status.push_back(static_cast<std::uint8_t>(nibble(text[i]) * 16 + nibble(text[i + 1])));
  return b;
}

std::string JobKey(const std::string& spec) {
  std::uint64_t h = 1469598103934665603ULL;
  for (unsigned char c : spec) h = (h ^ c) * 1099511628211ULL;
  return fmt::format("{:016x}", h);
}

nlohmann::json EmptinessJobSpec(const ParamBox& box, const LpBasis& warm, bool cheap_windows) {
  return {{"kind", kEmptinessKind}, {"box", BoxToJson(box)}, {"warm", EncodeBasis(warm)}, {"cheap", cheap_windows}};
}

nlohmann::json ObjectiveJobSpec(const ParamBox& start, const std::vector<ParamBox>& boxes, const Objective& objective,
                                std::optional<double> target, double target_gap,
                                const std::vector<ParameterForm>& forms, std::optional<int> lp_budget,
                                const std::optional<ParamBox>& scale) {
  nlohmann::json list = nlohmann::json::array();
  for (const auto& b : boxes) list.push_back(BoxToJson(b));
  nlohmann::json j = {{"kind", kObjectiveKind}, {"start", BoxToJson(start)}, {"boxes", list},
                      {"parameter", objective.parameter}, {"maximise", objective.maximise}, {"target_gap", target_gap}};
  j["target"] = target ? nlohmann::json(*target) : nlohmann::json(nullptr);
  if (!forms.empty()) j["forms"] = FormsToJson(forms);
  if (lp_budget) j["lp_budget"] = *lp_budget;
  if (scale) j["scale"] = BoxToJson(*scale);
  return j;
}

EmptinessAnswer EmptinessAnswer::from_json(const nlohmann::json& j) {
  EmptinessAnswer a;
  a.verdict = j.at("pruned").get<bool>() ? BoxVerdict::kPruned : BoxVerdict::kKept;
  if (j.contains("certificate")) a.certificate = PruneCertificate::from_json(j.at("certificate"));
  a.point = j.at("point").get<std::vector<double>>();
  a.basis = DecodeBasis(j.at("basis").get<std::string>());
  a.lps = j.at("lps").get<int>();
  a.lp_failures = j.at("lp_failures").get<int>();
  return a;
}

sdp::JobFunction MakeExactJobFunction(const LiftedData& data, const ExactJobSettings& settings) {
  return [&data, settings](const std::string& text) {
    const nlohmann::json spec = nlohmann::json::parse(text);
    auto solver = MakeLpSolver(settings.lp_solver);
    if (KindOf(spec) == JobKind::kEmptiness) {
      BoxEvaluationOptions evaluation = settings.evaluation;
      if (!spec.at("cheap").get<bool>()) evaluation.cheap_windows = 0;
      const BoxEvaluation e = TestBoxEmpty(data, BoxFromJson(spec.at("box")), evaluation, *solver,
                                           DecodeBasis(spec.at("warm").get<std::string>()));
      nlohmann::json out = {{"pruned", e.verdict == BoxVerdict::kPruned}, {"point", e.point},
                            {"basis", EncodeBasis(e.basis)}, {"lps", e.lps}, {"lp_failures", e.lp_failures}};
      if (e.certificate) out["certificate"] = e.certificate->to_json();
      return out.dump();
    }
    std::vector<ParamBox> boxes;
    for (const auto& b : spec.at("boxes")) boxes.push_back(BoxFromJson(b));
    const Objective objective{spec.at("parameter").get<int>(), spec.at("maximise").get<bool>()};
    std::optional<double> target;
    if (!spec.at("target").is_null()) target = spec.at("target").get<double>();
    ObjectiveSearchOptions search = settings.search;
    if (spec.contains("lp_budget")) search.lp_budget = spec.at("lp_budget").get<int>();
    // The forms travel in the spec: an MPI rank's data has none of the coordinator's.
    LiftedData with_forms;
    if (spec.contains("forms")) {
      with_forms = data;
      with_forms.forms = FormsFromJson(spec.at("forms"));
    }
    std::optional<ParamBox> scale;
    if (spec.contains("scale")) scale = BoxFromJson(spec.at("scale"));
    const ObjectiveSearchResult r =
        SearchObjective(spec.contains("forms") ? with_forms : data, BoxFromJson(spec.at("start")), boxes, objective,
                        target, spec.at("target_gap").get<double>(), search, settings.evaluation, *solver,
                        scale ? &*scale : nullptr);
    return r.to_json().dump();
  };
}

}  // namespace hw::exact
