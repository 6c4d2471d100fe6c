// Concealed-effect study of `hwbounds diagnose`: for every effect of the vocabulary (at its usual
// location, plus deadzone, saturation and quantization at the output), SEEDS scenarios (scenario.hpp:
// randomised second-order system, low-passed random-step input, effect RMS 1.5 / 2.25 / 3 times the
// noise standard deviation, 4–8 % of the output's standard deviation) plus NULLS null scenarios; run
// once with the true nominal model handed over (as `--model` would) and once per fitted nominal
// structure (as `--fit` would).
// Writes OUT/diagnose_study.md and OUT/diagnose_study.json (confusion matrices, named-right rate,
// false alarms, window IoU, validation fit gain).
// Usage: diagnose_study [OUT_DIR] [SEEDS] [SAMPLES] [FIRST_SEED] [NOMINALS] [NULLS] [RATIOS]
//   defaults: diagnose_study_out 5 2000 1001 design,linear:2,2 10 1,1.5,2,2.5,3
// RATIOS (effect RMS / noise standard deviation) are cycled over the seeds.
// The reported study uses seeds 1001.. ; development and tests/diagnose_study_test.cpp use seeds 1..99.
#include <filesystem>
#include <sstream>
#include <string>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "core/atomic_write.hpp"
#include "diagnose/study.hpp"

namespace {

std::vector<std::string> SplitList(const std::string& s) {
  std::vector<std::string> out;
  std::string item;
  std::istringstream in(s);
  // Items are separated by ';' or by ',' before a structure name ("design,linear:2,2").
  std::string token;
  while (std::getline(in, token, ',')) {
    const bool starts_new = token == "design" || token.rfind("linear:", 0) == 0 || token.rfind("hw:", 0) == 0;
    if (starts_new && !item.empty()) out.push_back(item), item.clear();
    item += (item.empty() ? "" : ",") + token;
  }
  if (!item.empty()) out.push_back(item);
  return out;
}

std::string Title(const std::string& nominal) {
  return nominal == "design" ? "the true nominal model (from design)"
                             : "`" + nominal + "` fitted by the tool on the identification recording";
}

}  // namespace

int main(int argc, char** argv) {
  using namespace hw::diagnose;
  const std::string out = argc > 1 ? argv[1] : "diagnose_study_out";
  const int seeds = argc > 2 ? std::stoi(argv[2]) : 5;
  const std::size_t samples = argc > 3 ? std::stoul(argv[3]) : 2000;
  const unsigned first_seed = argc > 4 ? static_cast<unsigned>(std::stoul(argv[4])) : 1001;
  const auto nominals = SplitList(argc > 5 ? argv[5] : "design,linear:2,2");
  const int nulls = argc > 6 ? std::stoi(argv[6]) : 10;
  const std::string ratio_text = argc > 7 ? argv[7] : "1,1.5,2,2.5,3";
  std::vector<double> ratios;
  {
    std::istringstream in(ratio_text);
    for (std::string tok; std::getline(in, tok, ',');) ratios.push_back(std::stod(tok));
  }
  std::string md = fmt::format("# Concealed-effect study of hwbounds diagnose\n\nCommand: `diagnose_study {} {} {} {} {} {} {}`\n\n",
                               out, seeds, samples, first_seed, argc > 5 ? argv[5] : "design,linear:2,2", nulls,
                               ratio_text);
  nlohmann::json js;
  double total = 0.0;
  for (const std::string& nominal : nominals) {
    StudyOptions o;
    o.seeds_per_effect = seeds;
    o.null_scenarios = nulls;
    o.samples = samples;
    o.first_seed = first_seed;
    o.nominal = nominal;
    o.ratios = ratios;
    const StudyResult r = RunStudy(o);
    total += r.seconds;
    md += fmt::format("## Nominal model: {}\n\n{} scenarios per effect and location (seeds {}–{}, effect RMS {} times "
                      "the noise standard deviation), {} null scenarios, {} samples per recording (identification and "
                      "validation each).\n\n{}\n",
                      Title(nominal), seeds, first_seed, first_seed + seeds - 1, ratio_text, nulls, samples,
                      r.to_markdown());
    std::string wrong;
    for (const auto& c : r.cases)
      if (c.truth != c.verdict || (c.truth != Effect::kNone && c.truth_location != c.verdict_location))
        wrong += fmt::format("- {}@{} seed {} ratio {:.2f} -> {} (window IoU {:.2f})\n", EffectName(c.truth),
                             LocationName(c.truth_location), c.seed, c.ratio, c.verdict_label, c.window_iou);
    md += "Not named right:\n\n" + (wrong.empty() ? std::string("- none\n") : wrong) + "\n";
    js[nominal] = r.to_json();
    fmt::print("{}: named right {:.1f} %, false alarms {}/{}, mean IoU {:.2f} ({:.1f} s)\n", nominal,
               100 * r.named_right_rate, r.false_alarms, r.null_cases, r.mean_window_iou, r.seconds);
  }
  md += fmt::format("Total run time {:.1f} s.\n", total);
  std::filesystem::create_directories(out);
  hw::write_text_atomic(out + "/diagnose_study.md", md);
  hw::write_text_atomic(out + "/diagnose_study.json", js.dump(2) + "\n");
  fmt::print("{}", md);
  fmt::print("wrote {0}/diagnose_study.md and {0}/diagnose_study.json\n", out);
  return 0;
}
