// Where the effects of an open-study run's misses can be seen: for each scenario with a miss, the part of
// the effect that the nominal structure, refitted to the noise-free output, cannot absorb (its visible
// RMS, in noise standard deviations) on the whole identification recording (the generator's size), on its
// held-out tail (last third) and on the validation recording. A miss whose effect stays below HALF noise
// standard deviations on the tail or on validation could not pass the diagnosis' held-out or validation
// test whatever the method does.
//
// Usage: diagnose_open_sizes RUN_DIR [HALF=0.5]   (RUN_DIR holds the open_study.json of diagnose_open_study)
#include <cmath>
#include <fstream>
#include <map>
#include <string>

#include <fmt/format.h>

#include "core/input_error.hpp"
#include "diagnose/open_scenario.hpp"
#include "diagnose/open_study.hpp"
#include "diagnose/refit.hpp"

using namespace hw::diagnose;

namespace {

struct Visible {
  double all = 0.0, tail = 0.0;
};

// Visible RMS of the effect on a recording, in noise standard deviations (u in deviations).
Visible VisibleOn(const OpenScenario& sc, const Recording& rec) {
  std::vector<double> u = rec.u;
  for (auto& v : u) v -= sc.u_offset;
  const std::vector<double> y = sc.truth.simulate(u);
  const Segment all{&u, &y, 0, 0};
  const std::vector<double> yh = RefitModel(sc.truth.WithoutBlocks(), all, RefitOptions{}).model.simulate(u);
  const std::size_t n = y.size(), tail_from = n * 2 / 3;
  double s_all = 0.0, s_tail = 0.0;
  for (std::size_t t = 0; t < n; ++t) {
    const double e = (y[t] - yh[t]) * (y[t] - yh[t]);
    s_all += e;
    if (t >= tail_from) s_tail += e;
  }
  return {std::sqrt(s_all / n) / sc.noise_std, std::sqrt(s_tail / (n - tail_from)) / sc.noise_std};
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    fmt::print(stderr, "usage: diagnose_open_sizes RUN_DIR [HALF=0.5]\n");
    return 2;
  }
  try {
    const std::string path = std::string(argv[1]) + "/open_study.json";
    std::ifstream in(path);
    if (!in) throw hw::InputError(path + ": cannot be read");
    const double half = argc > 2 ? std::stod(argv[2]) : 0.5;
    const OpenStudyResult res = OpenStudyResult::FromJson(nlohmann::json::parse(in));
    std::map<std::pair<unsigned, std::string>, std::string> missed;  // (seed, row) -> modes missed
    for (const auto& c : res.cases)
      if (!c.named_right && c.row != "none") missed[{c.seed, c.row}] += (missed[{c.seed, c.row}].empty() ? "" : ",") + NominalModeName(c.mode);
    int hidden = 0;
    fmt::print("| row | seed | missed with | size (ident) | held-out tail | validation |\n|---|---|---|---|---|---|\n");
    for (const auto& [key, modes] : missed) {
      OpenScenarioOptions so;
      const auto at = key.second.find('@');
      so.effect = ParseEffect(key.second.substr(0, at));
      so.location = ParseLocation(key.second.substr(at + 1));
      so.seed = key.first;
      const OpenScenario sc = MakeOpenScenario(so);
      const Visible id = VisibleOn(sc, sc.ident), va = VisibleOn(sc, sc.valid);
      const bool out_of_sight = id.tail < half || va.all < half;
      hidden += out_of_sight;
      fmt::print("| `{}` | {} | {} | {:.2f} | {:.2f} | {:.2f}{} |\n", key.second, key.first, modes, id.all, id.tail, va.all,
                 out_of_sight ? " (below the bar)" : "");
    }
    fmt::print("\n{} of {} scenarios with a miss have their effect below {} noise standard deviations on the held-out tail "
               "or on validation.\n", hidden, missed.size(), half);
  } catch (const std::exception& e) {
    fmt::print(stderr, "error: {}\n", e.what());
    return 2;
  }
  return 0;
}
