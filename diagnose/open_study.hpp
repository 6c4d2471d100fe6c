#pragma once
// The open study: scenarios from the second generator (open_scenario.hpp), diagnosed once with the
// true nominal handed over (as --model) and once with the nominal's structure fitted by the tool
// (as --fit), scored per effect class with Wilson 95 % intervals. Tuning and reporting use disjoint
// seed ranges (the caller chooses first_seed).
#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "diagnose/diagnose.hpp"
#include "diagnose/open_scenario.hpp"
#include "diagnose/scenario.hpp"

namespace hw::diagnose {

enum class NominalMode { kGiven, kFitted };
std::string NominalModeName(NominalMode m);

struct OpenStudyOptions {
  std::vector<std::pair<Effect, Location>> rows;  // empty = OpenStudyRows()
  int scenarios_per_row = 2;  // per effect@location row
  int null_scenarios = 4;
  unsigned first_seed = 1;    // scenario i uses seed first_seed + i
  std::vector<NominalMode> modes = {NominalMode::kGiven, NominalMode::kFitted};
  OpenScenarioOptions scenario;  // effect, location and seed are set per scenario
  bool progress = false;         // one line per diagnosis on stderr
  int shard = 0, shards = 1;     // run only scenarios i with i % shards == shard (seeds stay first_seed + i)
  // Called after every scenario with the cases so far (e.g. to write partial results atomically).
  std::function<void(const struct OpenStudyResult&)> on_scenario;
  // The partial result of an earlier run of the same study: its scenarios (a seed with a case for every mode,
  // or skipped) are taken from it, not diagnosed again — a stopped run resumes.
  const struct OpenStudyResult* resume = nullptr;
  DiagnoseOptions diagnose;
  bool IsValid(std::string* error) const;
};

struct OpenCase {
  std::string row;       // true effect@location or "none"
  std::string verdict;   // verdict label ("none" without one)
  NominalMode mode = NominalMode::kGiven;
  NominalStatus status = NominalStatus::kReachedNoiseFloor;
  bool named_right = false;  // the verdict's first block is the true effect at its location (none for null)
  unsigned seed = 0;
  double ratio = 0.0, noise_std = 0.0;
  double nominal_holdout_rmse = 0.0;  // the baseline's held-out RMSE
  std::string input, structure;
  std::string best_candidate;  // the best-ranked single block and its evidence (why it was or was not named)
  bool offset = false, feedback_detected = false;
  double seconds = 0.0;
  nlohmann::json to_json() const;
};

// A proportion with its Wilson score 95 % interval.
struct Proportion {
  int k = 0, n = 0;
  double rate() const { return n ? double(k) / n : 0.0; }
  double lower() const;
  double upper() const;
  std::string Text() const;  // "27/30 = 90.0 % [74.4, 96.5]"
};

struct OpenStudyResult {
  std::vector<OpenCase> cases;
  std::vector<std::string> rows;  // effect rows, then none
  std::vector<unsigned> skipped_seeds;  // no usable scenario for the seed (said in the report)
  double seconds = 0.0;
  Proportion PerRow(const std::string& row, NominalMode mode) const;
  Proportion NullReachesNoise(NominalMode mode) const;  // null cases whose baseline held-out RMSE <= 1.2 x noise
  Proportion NullFailReported(NominalMode mode) const;  // null cases above it that are reported as failed fits
  nlohmann::json to_json() const;
  std::string to_markdown(const std::string& command, bool verbose = false) const;  // verbose: evidence of misses
  // Reads the cases of to_json() back (to merge shards); throws InputError.
  static OpenStudyResult FromJson(const nlohmann::json& j);
  void Merge(const OpenStudyResult& other);
};

// The rows: every effect at its usual location plus deadzone, saturation and quantization at the output.
std::vector<std::pair<Effect, Location>> OpenStudyRows();
OpenStudyResult RunOpenStudy(const OpenStudyOptions& options);

}  // namespace hw::diagnose
