#include "diagnose/open_study.hpp"

#include <chrono>
#include <cmath>

#include <fmt/format.h>

#include "core/csv_table.hpp"

namespace hw::diagnose {
namespace {

std::string RowName(Effect e, Location l) { return e == Effect::kNone ? "none" : EffectName(e) + "@" + LocationName(l); }

OpenCase RunOne(const OpenStudyOptions& o, const OpenScenario& sc, const std::string& row, NominalMode mode) {
  DiagnoseReport r;
  if (mode == NominalMode::kGiven) {
    Diagnose(o.diagnose, sc.nominal, nullptr, sc.ident, sc.valid, &r);
  } else {
    // As --fit does: the structure is fitted on the identification recording (operating point removed
    // inside Diagnose), then diagnosed with that structure known.
    DiagnoseOptions d = o.diagnose;
    Diagnose(d, FitNominalForDiagnosis(sc.structure, sc.ident, d).model, &sc.structure, sc.ident, sc.valid, &r);
  }
  OpenCase c;
  c.row = row;
  c.mode = mode;
  c.seed = 0;
  c.verdict = r.verdict == Effect::kNone ? "none" : r.augmented_model.Label();
  c.status = r.nominal_status;
  const std::string first = r.verdict == Effect::kNone ? "none" : RowName(r.verdict, r.verdict_location);
  c.named_right = first == row;
  c.ratio = sc.ratio;
  c.noise_std = sc.noise_std;
  c.nominal_holdout_rmse = r.baseline_holdout_rmse;
  c.input = InputKindName(sc.input);
  c.structure = sc.structure.Text();
  c.offset = sc.u_offset != 0.0;
  c.feedback_detected = r.feedback.detected;
  c.seconds = r.seconds;
  if (!r.findings.empty()) c.best_candidate = r.findings.front().Label() + ": " + r.findings.front().evidence;
  for (const auto& f : r.findings)
    if (f.Label() == row && &f != &r.findings.front()) c.best_candidate += " | true row: " + f.evidence;
  return c;
}

}  // namespace

std::string NominalModeName(NominalMode m) { return m == NominalMode::kGiven ? "given" : "fitted"; }

bool OpenStudyOptions::IsValid(std::string* error) const {
  if (scenarios_per_row < 0 || null_scenarios < 0 || modes.empty()) {
    if (error) *error = "open study: scenarios_per_row >= 0, null_scenarios >= 0 and at least one mode required";
    return false;
  }
  return scenario.IsValid(error) && diagnose.IsValid(error);
}

double Proportion::lower() const {
  if (n == 0) return 0.0;
  const double z = 1.959964, p = rate(), d = 1 + z * z / n;
  return std::max(0.0, (p + z * z / (2 * n) - z * std::sqrt(p * (1 - p) / n + z * z / (4.0 * n * n))) / d);
}

double Proportion::upper() const {
  if (n == 0) return 1.0;
  const double z = 1.959964, p = rate(), d = 1 + z * z / n;
  return std::min(1.0, (p + z * z / (2 * n) + z * std::sqrt(p * (1 - p) / n + z * z / (4.0 * n * n))) / d);
}

std::string Proportion::Text() const {
  return fmt::format("{}/{} = {:.1f} % [{:.1f}, {:.1f}]", k, n, 100 * rate(), 100 * lower(), 100 * upper());
}

nlohmann::json OpenCase::to_json() const {
  return {{"row", row},           {"verdict", verdict},   {"mode", NominalModeName(mode)},
          {"status", NominalStatusName(status)}, {"named_right", named_right}, {"seed", seed},
          {"ratio", ratio},       {"noise_std", noise_std}, {"nominal_holdout_rmse", nominal_holdout_rmse},
          {"input", input},       {"structure", structure}, {"offset", offset},
          {"feedback_detected", feedback_detected}, {"seconds", seconds}, {"best_candidate", best_candidate}};
}

std::vector<std::pair<Effect, Location>> OpenStudyRows() {
  std::vector<std::pair<Effect, Location>> rows;
  for (const auto& n : EffectVocabulary())
    if (n != "none") rows.emplace_back(ParseEffect(n), DefaultLocation(ParseEffect(n)));
  for (Effect e : {Effect::kDeadzone, Effect::kSaturation, Effect::kQuantization}) rows.emplace_back(e, Location::kOutput);
  return rows;
}

Proportion OpenStudyResult::PerRow(const std::string& row, NominalMode mode) const {
  Proportion p;
  for (const auto& c : cases)
    if (c.row == row && c.mode == mode) ++p.n, p.k += c.named_right;
  return p;
}

Proportion OpenStudyResult::NullReachesNoise(NominalMode mode) const {
  Proportion p;
  for (const auto& c : cases)
    if (c.row == "none" && c.mode == mode) ++p.n, p.k += c.nominal_holdout_rmse <= 1.2 * c.noise_std;
  return p;
}

Proportion OpenStudyResult::NullFailReported(NominalMode mode) const {
  Proportion p;
  for (const auto& c : cases)
    if (c.row == "none" && c.mode == mode && c.nominal_holdout_rmse > 1.2 * c.noise_std)
      ++p.n, p.k += c.status == NominalStatus::kFailed;
  return p;
}

nlohmann::json OpenStudyResult::to_json() const {
  nlohmann::json j;
  j["seconds"] = seconds;
  for (const auto& c : cases) j["cases"].push_back(c.to_json());
  for (NominalMode m : {NominalMode::kGiven, NominalMode::kFitted})
    for (const auto& row : rows) {
      const Proportion p = PerRow(row, m);
      if (p.n) j["per_row"][NominalModeName(m)][row] = {{"k", p.k}, {"n", p.n}, {"rate", p.rate()}, {"wilson95", {p.lower(), p.upper()}}};
    }
  return j;
}

std::string OpenStudyResult::to_markdown(const std::string& command, bool verbose) const {
  std::string s = "# Open diagnosis study (second scenario generator)\n\n";
  s += fmt::format("Command: `{}`\n\n{} diagnoses in {:.0f} s. Rate of verdicts that name the true effect at its "
                   "location (for `none`: no false alarm), with Wilson 95 % intervals.\n\n",
                   command, cases.size(), seconds);
  s += "| row | nominal given | nominal fitted |\n|---|---|---|\n";
  for (const auto& row : rows)
    s += fmt::format("| `{}` | {} | {} |\n", row, PerRow(row, NominalMode::kGiven).Text(), PerRow(row, NominalMode::kFitted).Text());
  Proportion eff[2];
  for (const auto& c : cases)
    if (c.row != "none") ++eff[c.mode == NominalMode::kFitted].n, eff[c.mode == NominalMode::kFitted].k += c.named_right;
  s += fmt::format("| all effects | {} | {} |\n\n", eff[0].Text(), eff[1].Text());
  s += fmt::format("Null cases whose baseline reaches held-out RMSE <= 1.2 x the true noise: given {}, fitted {}.\n",
                   NullReachesNoise(NominalMode::kGiven).Text(), NullReachesNoise(NominalMode::kFitted).Text());
  s += fmt::format("Of the null cases above it, reported as a failed fit: given {}, fitted {}.\n\n",
                   NullFailReported(NominalMode::kGiven).Text(), NullFailReported(NominalMode::kFitted).Text());
  if (!skipped_seeds.empty()) {
    s += "Seeds without a usable scenario (the system diverged or the effect was invisible after 8 draws):";
    for (unsigned v : skipped_seeds) s += fmt::format(" {}", v);
    s += "\n\n";
  }
  s += "Misses (row, mode, seed, input, structure, ratio, verdict):\n\n";
  for (const auto& c : cases)
    if (!c.named_right)
      s += fmt::format("* `{}` {} seed {} {} `{}`{} ratio {:.2f}: `{}` ({})\n", c.row, NominalModeName(c.mode), c.seed,
                       c.input, c.structure, c.offset ? " offset" : "", c.ratio, c.verdict, NominalStatusName(c.status));
  if (verbose)
    for (const auto& c : cases)
      if (!c.named_right) s += fmt::format("  * seed {} {}: {}\n", c.seed, NominalModeName(c.mode), c.best_candidate);
  return s;
}

OpenStudyResult RunOpenStudy(const OpenStudyOptions& o) {
  std::string err;
  if (!o.IsValid(&err)) throw InputError(err);
  const auto t0 = std::chrono::steady_clock::now();
  OpenStudyResult res;
  const auto rows = o.rows.empty() ? OpenStudyRows() : o.rows;
  for (const auto& [e, l] : rows) res.rows.push_back(RowName(e, l));
  res.rows.push_back("none");
  std::vector<std::pair<Effect, Location>> plan;
  for (int s = 0; s < o.scenarios_per_row; ++s)
    for (const auto& r : rows) plan.push_back(r);
  for (int s = 0; s < o.null_scenarios; ++s) plan.emplace_back(Effect::kNone, Location::kInput);
  for (std::size_t i = 0; i < plan.size(); ++i) {
    OpenScenarioOptions so = o.scenario;
    so.effect = plan[i].first;
    so.location = plan[i].second;
    so.seed = o.first_seed + static_cast<unsigned>(i);
    OpenScenario sc;
    try {
      sc = MakeOpenScenario(so);
    } catch (const InputError& e) {  // no usable draw for this seed: reported, not silently skipped
      fmt::print(stderr, "seed {}: {}\n", so.seed, e.what());
      res.skipped_seeds.push_back(so.seed);
      continue;
    }
    for (NominalMode m : o.modes) {
      OpenCase c;
      try {
        c = RunOne(o, sc, RowName(plan[i].first, plan[i].second), m);
      } catch (const InputError& e) {  // counted as a miss, with the reason
        c.row = RowName(plan[i].first, plan[i].second);
        c.mode = m;
        c.verdict = std::string("error: ") + e.what();
        c.named_right = false;
      }
      c.seed = so.seed;
      res.cases.push_back(c);
      if (o.progress) fmt::print(stderr, "{} {} seed {}: {} ({:.1f} s)\n", c.row, NominalModeName(m), c.seed, c.verdict, c.seconds);
    }
  }
  res.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return res;
}

}  // namespace hw::diagnose
