#include "diagnose/open_study.hpp"

#include <algorithm>
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
  if (scenarios_per_row < 0 || null_scenarios < 0 || modes.empty() || shards < 1 || shard < 0 || shard >= shards) {
    if (error) *error = "open study: scenarios_per_row >= 0, null_scenarios >= 0, 0 <= shard < shards and at least one mode required";
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

OpenStudyResult OpenStudyResult::FromJson(const nlohmann::json& j) {
  OpenStudyResult r;
  try {
    for (const auto& row : OpenStudyRows()) r.rows.push_back(RowName(row.first, row.second));
    r.rows.push_back("none");
    r.seconds = j.value("seconds", 0.0);
    for (const auto& v : j.value("skipped_seeds", nlohmann::json::array())) r.skipped_seeds.push_back(v.get<unsigned>());
    for (const auto& jc : j.value("cases", nlohmann::json::array())) {
      OpenCase c;
      c.row = jc.at("row").get<std::string>();
      c.verdict = jc.at("verdict").get<std::string>();
      c.mode = jc.at("mode").get<std::string>() == "given" ? NominalMode::kGiven : NominalMode::kFitted;
      const std::string st = jc.at("status").get<std::string>();
      for (NominalStatus s : {NominalStatus::kReachedNoiseFloor, NominalStatus::kExplainedByEffect, NominalStatus::kFailed})
        if (NominalStatusName(s) == st) c.status = s;
      c.named_right = jc.at("named_right").get<bool>();
      c.seed = jc.at("seed").get<unsigned>();
      c.ratio = jc.at("ratio").get<double>();
      c.noise_std = jc.at("noise_std").get<double>();
      c.nominal_holdout_rmse = jc.at("nominal_holdout_rmse").get<double>();
      c.input = jc.at("input").get<std::string>();
      c.structure = jc.at("structure").get<std::string>();
      c.offset = jc.at("offset").get<bool>();
      c.feedback_detected = jc.at("feedback_detected").get<bool>();
      c.seconds = jc.at("seconds").get<double>();
      c.best_candidate = jc.value("best_candidate", "");
      r.cases.push_back(c);
    }
  } catch (const nlohmann::json::exception& e) {
    throw InputError(std::string("open study results: ") + e.what());
  }
  return r;
}

void OpenStudyResult::Merge(const OpenStudyResult& other) {
  cases.insert(cases.end(), other.cases.begin(), other.cases.end());
  skipped_seeds.insert(skipped_seeds.end(), other.skipped_seeds.begin(), other.skipped_seeds.end());
  seconds += other.seconds;
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
  j["skipped_seeds"] = skipped_seeds;
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
  s += fmt::format("Command: `{}`\n\n{} diagnoses in {:.0f} s (sum over processes). Rate of verdicts that name the true effect at its "
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

namespace {

// Copies seed's cases (one per mode) or its skip from an earlier run into res; false when that run did not
// finish the scenario (it is then diagnosed).
bool TakeFromEarlierRun(const OpenStudyResult& earlier, unsigned seed, const std::vector<NominalMode>& modes,
                        OpenStudyResult& res) {
  if (std::find(earlier.skipped_seeds.begin(), earlier.skipped_seeds.end(), seed) != earlier.skipped_seeds.end()) {
    res.skipped_seeds.push_back(seed);
    return true;
  }
  std::vector<OpenCase> found;
  for (NominalMode m : modes)
    for (const auto& c : earlier.cases)
      if (c.seed == seed && c.mode == m) {
        found.push_back(c);
        break;
      }
  if (found.size() != modes.size()) return false;
  res.cases.insert(res.cases.end(), found.begin(), found.end());
  return true;
}

}  // namespace

OpenStudyResult RunOpenStudy(const OpenStudyOptions& o) {
  std::string err;
  if (!o.IsValid(&err)) throw InputError(err);
  const auto t0 = std::chrono::steady_clock::now();
  OpenStudyResult res;
  const auto rows = o.rows.empty() ? OpenStudyRows() : o.rows;
  for (const auto& [e, l] : rows) res.rows.push_back(RowName(e, l));
  res.rows.push_back("none");
  // Rounds of every effect row, the null scenarios spread over the rounds, so that a partial run
  // holds every class in proportion.
  std::vector<std::pair<Effect, Location>> plan;
  const int rounds = std::max(o.scenarios_per_row, 1);
  for (int s = 0; s < rounds; ++s) {
    if (s < o.scenarios_per_row)
      for (const auto& r : rows) plan.push_back(r);
    for (int k = 0; k < o.null_scenarios; ++k)
      if (k % rounds == s) plan.emplace_back(Effect::kNone, Location::kInput);
  }
  for (std::size_t i = 0; i < plan.size(); ++i) {
    if (static_cast<int>(i % o.shards) != o.shard) continue;
    if (o.resume && TakeFromEarlierRun(*o.resume, o.first_seed + static_cast<unsigned>(i), o.modes, res)) continue;
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
    res.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    if (o.on_scenario) o.on_scenario(res);
  }
  res.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() +
                (o.resume ? o.resume->seconds : 0.0);
  return res;
}

}  // namespace hw::diagnose
