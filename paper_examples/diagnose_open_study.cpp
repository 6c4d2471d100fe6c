// Open study of `hwbounds diagnose` on the second scenario generator (diagnose/open_scenario.hpp):
// randomised orders, poles, static maps, inputs (multisine, PRBS, steps, filtered noise, closed loop),
// effect sizes 0.5-3 noise standard deviations, record lengths and operating-point offsets; every
// scenario is diagnosed with the true nominal given (--model) and with its structure fitted (--fit).
// Writes OUT/open_study.md and OUT/open_study.json (per-class rates with Wilson 95 % intervals, misses).
//
// Usage: diagnose_open_study OUT [PER_ROW] [NULLS] [FIRST_SEED] [MODES]
//   defaults: PER_ROW 2, NULLS 4, FIRST_SEED 100001, MODES given,fitted
// Seed ranges: 1..99999 are for tuning (development runs), 100001.. for the reported results.
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include <fmt/format.h>

#include "core/csv_table.hpp"
#include "diagnose/open_study.hpp"

int main(int argc, char** argv) {
  using namespace hw::diagnose;
  if (argc < 2) {
    fmt::print(stderr, "usage: diagnose_open_study OUT [PER_ROW] [NULLS] [FIRST_SEED] [given,fitted]\n");
    return 2;
  }
  try {
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
    o.diagnose.threads = 1;
    o.progress = true;
    std::string command = "build/paper_examples/diagnose_open_study";
    for (int i = 1; i < argc; ++i) command += std::string(" ") + argv[i];
    const OpenStudyResult res = RunOpenStudy(o);
    std::filesystem::create_directories(out);
    auto write = [&](const std::string& name, const std::string& text) {
      const std::string path = out + "/" + name, tmp = path + ".tmp";
      std::ofstream(tmp) << text;
      std::filesystem::rename(tmp, path);
    };
    const std::string md = res.to_markdown(command);
    write("open_study.md", md);
    write("open_study.json", res.to_json().dump(1));
    fmt::print("{}", std::getenv("DIAGNOSE_STUDY_VERBOSE") ? res.to_markdown(command, true) : md);
  } catch (const std::exception& e) {
    fmt::print(stderr, "error: {}\n", e.what());
    return 2;
  }
  return 0;
}
