// Open study of `hwbounds diagnose` on the second scenario generator (diagnose/open_scenario.hpp):
// randomised orders, poles, static maps, inputs (multisine, PRBS, steps, filtered noise, closed loop),
// effect sizes 0.5-3 noise standard deviations, record lengths and operating-point offsets; every
// scenario is diagnosed with the true nominal given (--model) and with its structure fitted (--fit).
// Writes OUT/open_study.md and OUT/open_study.json (per-class rates with Wilson 95 % intervals, misses),
// rewritten atomically after every scenario so that a run stopped early still leaves its results; the same
// command on the same OUT resumes such a run (its finished scenarios are read back, not diagnosed again).
//
// Usage: diagnose_open_study OUT [PER_ROW] [NULLS] [FIRST_SEED] [MODES] [SHARD/SHARDS] [ROWS]
//        diagnose_open_study --merge OUT DIR...   (one table from the shards' open_study.json)
//   defaults: PER_ROW 2, NULLS 4, FIRST_SEED 100001, MODES given,fitted, SHARD/SHARDS 0/1,
//   ROWS every effect row (or a comma-separated subset such as stiction@input,backlash@input, for
//   development runs on the tuning seeds)
// Seed ranges: 1..99999 are for tuning (development runs); from 100001 on, each reporting range is run
// once with the method frozen and is retired (a development range) afterwards (docs/diagnose.md, "Open study").
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <optional>
#include <string>

#include <fmt/format.h>

#include "core/csv_table.hpp"
#include "diagnose/open_study.hpp"

namespace {

using namespace hw::diagnose;

void WriteResults(const OpenStudyResult& res, const std::string& out, const std::string& command) {
  std::filesystem::create_directories(out);
  auto write = [&](const std::string& name, const std::string& text) {
    const std::string path = out + "/" + name, tmp = path + ".tmp";
    std::ofstream(tmp) << text;
    std::filesystem::rename(tmp, path);
  };
  write("open_study.md", res.to_markdown(command));
  write("open_study.json", res.to_json().dump(1));
}

std::string CommandLine(int argc, char** argv) {
  std::string command = "build/paper_examples/diagnose_open_study";
  for (int i = 1; i < argc; ++i) command += std::string(" ") + argv[i];
  return command;
}

// The results an earlier run of the same command left in OUT (none when OUT holds none); an OUT written by
// another command is refused, so that a resumed study never mixes two.
std::optional<OpenStudyResult> EarlierRun(const std::string& out, const std::string& command) {
  std::ifstream json(out + "/open_study.json"), md(out + "/open_study.md");
  if (!json) return std::nullopt;
  std::string line, recorded;
  while (std::getline(md, line))
    if (line.rfind("Command: `", 0) == 0) recorded = line.substr(10, line.rfind('`') - 10);
  if (recorded != command)
    throw hw::InputError(fmt::format("{}/open_study.json: written by `{}`, not by this command; resume with that "
                                     "command or choose another OUT",
                                     out, recorded.empty() ? "an unknown command" : recorded));
  return OpenStudyResult::FromJson(nlohmann::json::parse(json));
}

int Merge(int argc, char** argv) {
  if (argc < 4) throw hw::InputError("--merge needs OUT and at least one shard directory");
  OpenStudyResult all;
  for (int i = 3; i < argc; ++i) {
    const std::string path = std::string(argv[i]) + "/open_study.json";
    std::ifstream in(path);
    if (!in) throw hw::InputError(path + ": cannot be read");
    const OpenStudyResult part = OpenStudyResult::FromJson(nlohmann::json::parse(in));
    if (i == 3) all = part;
    else all.Merge(part);
  }
  WriteResults(all, argv[2], CommandLine(argc, argv));
  fmt::print("{}", all.to_markdown(CommandLine(argc, argv)));
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    fmt::print(stderr, "usage: diagnose_open_study OUT [PER_ROW] [NULLS] [FIRST_SEED] [given,fitted] [SHARD/SHARDS] [ROWS]\n"
                       "       diagnose_open_study --merge OUT DIR...\n");
    return 2;
  }
  try {
    if (std::string(argv[1]) == "--merge") return Merge(argc, argv);
    const std::string out = argv[1];
    OpenStudyOptions o;
    o.scenarios_per_row = argc > 2 ? std::stoi(argv[2]) : 2;
    o.null_scenarios = argc > 3 ? std::stoi(argv[3]) : 4;
    o.first_seed = argc > 4 ? static_cast<unsigned>(std::stoul(argv[4])) : 100001;
    const std::string modes = argc > 5 ? argv[5] : "given,fitted";
    o.modes.clear();
    if (modes.find("given") != std::string::npos) o.modes.push_back(NominalMode::kGiven);
    if (modes.find("fitted") != std::string::npos) o.modes.push_back(NominalMode::kFitted);
    if (o.modes.empty()) throw hw::InputError("MODES must name given and/or fitted");
    if (argc > 6) {
      const std::string sh = argv[6];
      const auto slash = sh.find('/');
      if (slash == std::string::npos) throw hw::InputError("SHARD/SHARDS expected, e.g. 0/2");
      o.shard = std::stoi(sh.substr(0, slash));
      o.shards = std::stoi(sh.substr(slash + 1));
    }
    if (argc > 7) o.rows = ParseCandidates(argv[7]);
    o.diagnose.threads = 1;
    o.progress = true;
    const std::string command = CommandLine(argc, argv);
    const std::optional<OpenStudyResult> earlier = EarlierRun(out, command);
    if (earlier) {
      o.resume = &*earlier;
      fmt::print(stderr, "resuming: {} diagnoses read from {}/open_study.json\n", earlier->cases.size(), out);
    }
    o.on_scenario = [&](const OpenStudyResult& partial) { WriteResults(partial, out, command); };
    const OpenStudyResult res = RunOpenStudy(o);
    WriteResults(res, out, command);
    fmt::print("{}", res.to_markdown(command, std::getenv("DIAGNOSE_STUDY_VERBOSE") != nullptr));
  } catch (const std::exception& e) {
    fmt::print(stderr, "error: {}\n", e.what());
    return 2;
  }
  return 0;
}
