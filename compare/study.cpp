#include "compare/study.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <map>
#include <thread>

#include <fmt/format.h>

#include "compare/methods.hpp"
#include "core/atomic_write.hpp"
#include "core/input_error.hpp"
#include "dss/run_cache.hpp"
#include "sdp/job_executor.hpp"

namespace hw::compare {
namespace {

using nlohmann::json;
namespace fs = std::filesystem;

// A run's name in the run cache (its file: DIR/runs/<study key>/jobs/run_NNNN.json).
std::string RunName(int r) { return fmt::format("run_{:04d}", r); }

// What a study's runs depend on (scenario + methods + seed): its hash names the run cache's folder, so a rerun of
// the same study resumes from the files there and a different study never reads them.
json StudyInputs(const Scenario& s, const StudyOptions& o) {
  return {{"scenario", s.to_json()}, {"methods", o.methods}, {"seed", o.seed}};
}

// Lower is better for errors, higher for the fit.
bool HigherIsBetter(const std::string& q) { return q == "fit_pct"; }

json Stats(const std::vector<double>& v, bool higher_better) {
  const double n = static_cast<double>(v.size());
  double mean = 0.0;
  for (double x : v) mean += x / n;
  double ss = 0.0;
  for (double x : v) ss += (x - mean) * (x - mean);
  const double worst = higher_better ? *std::min_element(v.begin(), v.end()) : *std::max_element(v.begin(), v.end());
  return {{"n", v.size()}, {"mean", mean}, {"std", v.size() > 1 ? std::sqrt(ss / (n - 1)) : 0.0}, {"worst", worst}};
}

}  // namespace

bool StudyOptions::IsValid(std::string* error) const {
  auto fail = [&](std::string m) {
    if (error) *error = std::move(m);
    return false;
  };
  if (runs < 1) return fail("--runs must be >= 1");
  if (jobs < 0) return fail("--jobs must be >= 0");
  if (out_dir.empty()) return fail("--out DIR is required");
  const std::string known = fmt::format("{}", fmt::join(AllMethods(), ", "));
  if (methods.empty()) return fail("--methods needs at least one of " + known);
  for (const auto& m : methods)
    if (std::find(AllMethods().begin(), AllMethods().end(), m) == AllMethods().end())
      return fail(fmt::format("--methods: '{}' unknown; expected {}", m, known));
  return true;
}

json Aggregate(const Scenario& scenario, const std::vector<json>& runs) {
  json s = {{"scenario", scenario.name}, {"description", scenario.description}, {"runs", runs.size()},
            {"methods", json::object()}};
  bool coverage_ok = true, all_ok = true;
  std::vector<std::string> methods;
  for (const auto& r : runs)
    for (const auto& [name, m] : r.at("methods").items())
      if (std::find(methods.begin(), methods.end(), name) == methods.end()) methods.push_back(name);
  for (const auto& name : methods) {
    json ms;
    std::map<std::string, std::vector<double>> qv;
    std::vector<double> times;
    json failures = json::array(), not_available = json::object();
    std::map<std::string, json> cov;     // per parameter
    std::map<std::string, json> inside;  // per parameter
    int covered = 0, total = 0, guaranteed_runs = 0, sm_runs = 0;
    bool applicable = false;
    std::string reason;
    for (const auto& r : runs) {
      if (!r["methods"].contains(name)) continue;
      const auto& m = r["methods"][name];
      if (!m.value("applicable", false)) {
        reason = m.value("reason", "");
        continue;
      }
      applicable = true;
      if (m.contains("seconds")) times.push_back(m["seconds"].get<double>());
      if (MethodStatusOf(m) != MethodStatus::kOk) {
        failures.push_back({{"run", r["run"]}, {"message", m.value("message", "")}});
        all_ok = false;
        continue;
      }
      if (m.contains("quantities"))
        for (const auto& [q, v] : m["quantities"].items()) qv[q].push_back(v.get<double>());
      if (m.contains("not_available"))
        for (const auto& [q, v] : m["not_available"].items()) not_available[q] = v;
      if (m.contains("intervals")) {
        ++sm_runs;
        guaranteed_runs += m["coverage"]["all_guaranteed"].get<bool>();
        for (const auto& iv : m["intervals"]) {
          const std::string p = iv["name"];
          auto& c = cov[p];
          if (c.is_null()) c = {{"truth", iv["truth"]}, {"covered", 0}, {"runs", 0}, {"widths", json::array()}};
          c["covered"] = c["covered"].get<int>() + (iv["covered"].get<bool>() ? 1 : 0);
          c["runs"] = c["runs"].get<int>() + 1;
          c["widths"].push_back(iv["width"]);
          covered += iv["covered"].get<bool>();
          ++total;
          if (!iv["covered"].get<bool>()) coverage_ok = false;
        }
      }
      if (m.contains("inside_setmembership_intervals"))
        for (const auto& p : m["inside_setmembership_intervals"]["parameters"]) {
          auto& c = inside[p["name"].get<std::string>()];
          if (c.is_null()) c = {{"inside", 0}, {"runs", 0}, {"mapping", p["mapping"]}, {"max_projection_residual", 0.0}};
          c["inside"] = c["inside"].get<int>() + (p["inside"].get<bool>() ? 1 : 0);
          c["max_projection_residual"] =
              std::max(c["max_projection_residual"].get<double>(), p["projection_residual"].get<double>());
          c["runs"] = c["runs"].get<int>() + 1;
        }
    }
    ms["applicable"] = applicable;
    if (!applicable) {
      ms["reason"] = reason;
      s["methods"][name] = ms;
      continue;
    }
    ms["runs_ok"] = static_cast<int>(times.size()) - static_cast<int>(failures.size());
    ms["failures"] = failures;
    for (const auto& [q, v] : qv) ms["quantities"][q] = Stats(v, HigherIsBetter(q));
    for (const auto& [q, why] : not_available.items())
      if (!qv.count(q)) ms["not_available"][q] = why;
    if (!times.empty()) {
      auto t = Stats(times, false);
      double sum = 0.0;
      for (double x : times) sum += x;
      ms["time"] = {{"n", t["n"]}, {"mean", t["mean"]}, {"std", t["std"]}, {"max", t["worst"]}, {"total", sum}};
    }
    if (sm_runs > 0) {
      json per = json::object();
      for (auto& [p, c] : cov) {
        std::vector<double> w = c["widths"].get<std::vector<double>>();
        per[p] = {{"truth", c["truth"]}, {"covered", c["covered"]}, {"runs", c["runs"]},
                  {"width", Stats(w, false)}};
      }
      ms["coverage"] = {{"per_parameter", per}, {"covered", covered}, {"total", total},
                        {"runs_all_guaranteed", guaranteed_runs}, {"runs", sm_runs}};
    }
    if (!inside.empty()) {
      json per = json::object();
      for (auto& [p, c] : inside) per[p] = c;
      ms["inside_setmembership_intervals"] = per;
    }
    s["methods"][name] = ms;
  }
  s["coverage_ok"] = coverage_ok;
  s["all_ok"] = all_ok;
  return s;
}

StudySummary RunStudy(const StudyOptions& options, const Scenario& scenario) {
  std::string err;
  if (!options.IsValid(&err)) throw InputError(err);
  if (!scenario.IsValid(&err)) throw InputError("scenario " + scenario.name + ": " + err);
  const auto t0 = std::chrono::steady_clock::now();
  fs::create_directories(options.out_dir);
  write_text_atomic(options.out_dir + "/scenario.json", scenario.to_json().dump(2) + "\n");
  const json inputs = StudyInputs(scenario, options);
  const std::string key = dss::TextHash(inputs.dump());
  // The shared run cache (dss/run_cache.hpp): finished runs on disk, written atomically, damaged files recomputed.
  const dss::RunCache cache((fs::path(options.out_dir) / "runs").string(), key, inputs);
  StudySummary result;
  std::vector<int> pending;
  std::vector<std::string> names;
  for (int r = 0; r < options.runs; ++r) {
    names.push_back(RunName(r));
    if (cache.load(names.back())) ++result.runs_resumed;
    else pending.push_back(r);
  }
  cache.plan(names);
  int jobs = options.jobs > 0 ? options.jobs : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  jobs = std::min<int>(jobs, std::max<std::size_t>(1, pending.size()));
  if (!options.quiet)
    fmt::print(stderr, "compare: scenario {}, {} runs ({} to compute, {} resumed), {} worker processes\n",
               scenario.name, options.runs, pending.size(), result.runs_resumed, jobs);
  if (!pending.empty()) {
    // One forked process per run, each to whichever worker slot is free (sdp::ForkExecutor): run times differ by
    // 4x, and a fixed split left one worker with most of the slow runs. A run's result depends only on its index,
    // never on the worker; the parent writes each result file as it arrives.
    std::vector<std::string> specs;
    for (int r : pending) specs.push_back(std::to_string(r));
    const sdp::JobFunction run = [&](const std::string& spec) {
      return RunOne(scenario, options.methods, std::stoi(spec), options.seed).dump();
    };
    sdp::ForkExecutor executor(jobs);
    executor.Map(specs, run, [&](std::size_t i, const sdp::JobResult& answer) {
      const int r = pending[i];
      if (!answer.ok) {  // reported here; the missing result file is reported below
        fmt::print(stderr, "  run {}: {}\n", r, answer.error);
        return;
      }
      const json j = json::parse(answer.text);
      cache.store(RunName(r), j);
      if (options.quiet) return;
      std::string line = fmt::format("  run {:3d}:", r);
      for (const auto& [name, m] : j["methods"].items())
        if (m.value("applicable", false))
          line += fmt::format(" {} {} {:.1f} s;", name, m.value("status", "?"), m.value("seconds", 0.0));
      fmt::print(stderr, "{}\n", line);
    });
  }
  // Aggregate from the files only.
  std::vector<json> runs;
  std::vector<int> missing;
  for (int r = 0; r < options.runs; ++r) {
    if (auto j = cache.load(RunName(r))) runs.push_back(std::move(*j));
    else missing.push_back(r);
  }
  if (!missing.empty())
    throw std::runtime_error(fmt::format("compare: runs {} produced no result file (see the messages above); "
                                         "rerun the same command to retry only those",
                                         fmt::join(missing, ", ")));
  result.runs_computed = static_cast<int>(pending.size());
  result.summary = Aggregate(scenario, runs);
  result.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  result.summary["seed"] = options.seed;
  result.summary["jobs"] = jobs;
  result.summary["wall_seconds"] = result.wall_seconds;
  result.summary["runs_computed"] = result.runs_computed;
  result.summary["runs_resumed"] = result.runs_resumed;
  result.summary["study_key"] = key;
  result.summary["run_files"] = fs::relative(fs::path(cache.path()) / "jobs", options.out_dir).generic_string();
  result.coverage_ok = result.summary["coverage_ok"];
  result.all_ok = result.summary["all_ok"];
  if (options.plots) result.summary["plots_note"] = WritePlots(options.out_dir, scenario, runs, result.summary);
  write_text_atomic(options.out_dir + "/summary.json", result.summary.dump(2) + "\n");
  write_text_atomic(options.out_dir + "/summary.md", SummaryMarkdown(result.summary));
  result.message = fmt::format("{} runs ({} computed, {} resumed) in {:.1f} s with {} worker processes", options.runs,
                               result.runs_computed, result.runs_resumed, result.wall_seconds, jobs);
  return result;
}

}  // namespace hw::compare
