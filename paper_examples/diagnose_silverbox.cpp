// Discrepancy diagnosis on a real recording: Silverbox (Wigren & Schoukens, ECC 2013), an electronic
// mass–spring–damper with a nonlinear (cubic) spring, against a nominal linear output-error model.
//
// Slices of SNLS80mV.csv (0-based, half-open), inside the multisine part [40650, 127400) whose first
// 75 % is the usual estimation part and the rest the usual validation part:
//   identification [40600, 50650): 10 000 samples after 50 initialisation samples;
//   validation     [105662, 115712): 10 000 samples of the validation part after 50 initialisation samples.
// The first 50 samples of each slice only warm up the simulation (excluded from every cost and figure).
// Usage: diagnose_silverbox [OUT_DIR] [NA,NB]   (defaults: diagnose_silverbox_out, 2,3)
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>

#include <fmt/format.h>

#include "core/csv_table.hpp"
#include "diagnose/diagnose.hpp"

using namespace hw::diagnose;

namespace {

// SNLS80mV.csv has a quoted header with a trailing comma, which the project's strict CSV reader rejects.
void ReadSilverbox(const std::string& path, std::vector<double>* u, std::vector<double>* y) {
  std::ifstream in(path);
  if (!in) throw hw::InputError(path + ": cannot open (see /work/shared/data/README.md)");
  std::string line;
  std::getline(in, line);
  std::size_t no = 1;
  while (std::getline(in, line)) {
    ++no;
    if (line.find_first_not_of(" \t\r,") == std::string::npos) continue;  // blank last line
    double a = 0, b = 0;
    if (std::sscanf(line.c_str(), "%lf,%lf", &a, &b) != 2)
      throw hw::InputError(fmt::format("{}:{}: expected 'V1,V2,'", path, no));
    u->push_back(a);
    y->push_back(b);
  }
}

Recording Slice(const std::vector<double>& u, const std::vector<double>& y, std::size_t from, std::size_t to,
                const std::string& name) {
  Recording r;
  r.name = name;
  for (std::size_t i = from; i < to; ++i) {
    r.t.push_back(static_cast<double>(i));
    r.u.push_back(u[i]);
    r.y.push_back(y[i]);
  }
  return r;
}

}  // namespace

int main(int argc, char** argv) {
  const std::string out = argc > 1 ? argv[1] : "diagnose_silverbox_out";
  const std::string structure = argc > 2 ? argv[2] : "2,3";
  const std::string path = "/work/shared/data/silverbox/SNLS80mV.csv";
  std::vector<double> u, y;
  try {
    ReadSilverbox(path, &u, &y);
  } catch (const std::exception& e) {
    fmt::print(stderr, "error: {}\n", e.what());
    return 2;
  }
  const Recording ident = Slice(u, y, 40600, 50650, "SNLS80mV.csv [40600, 50650)");
  const Recording valid = Slice(u, y, 105662, 115712, "SNLS80mV.csv [105662, 115712)");
  DiagnoseOptions o;
  o.init_samples = 50;
  const hw::HwModel nominal = FitNominal(NominalSpec::Parse("linear:" + structure), {&ident.u, &ident.y, o.init_samples});
  DiagnoseReport r;
  Diagnose(o, nominal, ident, valid, &r);
  if (!r.ok) {
    fmt::print(stderr, "error: {}\n", r.message);
    return 1;
  }
  const auto files = WriteReport(r, ident, valid, out);
  fmt::print("Silverbox, nominal OE linear:{} fitted on the identification slice\n{}\n\n", structure, r.message);
  fmt::print("| model | validation RMSE (mV) | fit % |\n|---|---|---|\n");
  fmt::print("| nominal linear | {:.3f} | {:.2f} |\n", 1e3 * r.nominal.rmse, r.nominal.fit_percent);
  fmt::print("| nominal linear refitted | {:.3f} | {:.2f} |\n", 1e3 * r.nominal_refit.rmse, r.nominal_refit.fit_percent);
  fmt::print("| augmented ({}@{}) | {:.3f} | {:.2f} |\n\n", EffectName(r.augmented_model.block.effect),
             LocationName(r.augmented_model.block.location), 1e3 * r.augmented.rmse, r.augmented.fit_percent);
  fmt::print("noise std {:.4g} V (estimated), {} mismatch windows, region: {}\n", r.noise_std, r.windows.size(),
             r.region.description);
  fmt::print("ranked candidates:\n");
  for (const auto& f : r.findings)
    fmt::print("  {:<18} {:<7} score {:7.3f} ratio {:6.3f} z {:6.1f}  {}\n", EffectName(f.block.effect),
               LocationName(f.block.location), f.score, f.mse_ratio, f.z, f.block.to_json()["parameters"].dump());
  fmt::print("augmented model: {}\nrun time {:.2f} s; report in {}/report.md\n", r.augmented_model.to_json().dump(),
             r.seconds, out);
  return 0;
}
