// Concealed-effect study of `hwbounds diagnose`: for every effect of the vocabulary, SEEDS scenarios
// (scenario.hpp: randomised second-order system, low-passed random-step input, effect RMS 1.5 / 2.25 / 3
// times the noise standard deviation, 4–8 % of the output's standard deviation) plus SEEDS null
// scenarios (and deadzone, saturation, quantization also at the output); nominal model = output-error
// linear:2,2 fitted on the identification recording, and again with the true linear part as the
// nominal model "from design".
// Writes OUT/diagnose_study.md and OUT/diagnose_study.json (confusion matrix, false-alarm rate,
// location accuracy, window overlap, validation fit gain).
// Usage: diagnose_study [OUT_DIR] [SEEDS] [SAMPLES]   (defaults: diagnose_study_out, 10, 2000)
#include <filesystem>
#include <string>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "core/csv_table.hpp"
#include "diagnose/study.hpp"

int main(int argc, char** argv) {
  using namespace hw::diagnose;
  const std::string out = argc > 1 ? argv[1] : "diagnose_study_out";
  std::string md = "# Concealed-effect study of hwbounds diagnose\n\n";
  nlohmann::json js;
  double total = 0.0;
  // Two nominal models: fitted on the recording (the usual case), and the true linear part as a
  // model from design (as `--model` would hand it over).
  for (const std::string nominal : {"linear:2,2", "design"}) {
    StudyOptions o;
    o.seeds_per_effect = argc > 2 ? std::stoi(argv[2]) : 10;
    o.null_scenarios = o.seeds_per_effect;
    o.samples = argc > 3 ? std::stoul(argv[3]) : 2000;
    o.first_seed = 101;  // disjoint from the seeds of tests/diagnose_test.cpp
    o.nominal = nominal;
    const StudyResult r = RunStudy(o);
    total += r.seconds;
    md += fmt::format("## Nominal model: {}\n\n{} scenarios per effect and location, {} null scenarios, {} samples per "
                      "recording (identification and validation each).\n\n{}\n",
                      nominal == "design" ? "the true linear part (from design)" : "output-error " + nominal + " fitted on the identification recording",
                      o.seeds_per_effect, o.null_scenarios, o.samples, r.to_markdown());
    std::string wrong;
    for (const auto& c : r.cases)
      if (c.truth != c.verdict || (c.truth != Effect::kNone && c.truth_location != c.verdict_location))
        wrong += fmt::format("- {}@{} seed {} ratio {:.2f} -> {}{}\n", EffectName(c.truth), LocationName(c.truth_location),
                             c.seed, c.ratio, EffectName(c.verdict),
                             c.verdict == Effect::kNone ? "" : "@" + LocationName(c.verdict_location));
    md += "Misclassified:\n\n" + (wrong.empty() ? std::string("- none\n") : wrong) + "\n";
    js[nominal] = r.to_json();
  }
  md += fmt::format("Total run time {:.1f} s.\n", total);
  std::filesystem::create_directories(out);
  hw::write_text_atomic(out + "/diagnose_study.md", md);
  hw::write_text_atomic(out + "/diagnose_study.json", js.dump(2) + "\n");
  fmt::print("{}", md);
  fmt::print("wrote {0}/diagnose_study.md and {0}/diagnose_study.json\n", out);
  return 0;
}
