// Discrepancy diagnosis on real recordings with documented physics (docs/diagnose.md, "Real recordings"):
//  - Silverbox (Wigren & Schoukens 2013): electronic mass–spring–damper with a hardening (cubic) spring;
//  - Cascaded tanks (Schoukens, Mattsson, Wigren, Noël 2016): two water tanks, the lower one overflows
//    for large inputs (a saturated state), not in steady state at the start;
//  - EMPS (Janot, Gautier, Brunot 2019): a prismatic drive whose main nonlinearity is Coulomb friction
//    with asymmetric levels (force -> velocity, velocity from the filtered encoder position).
// For each: the nominal is fitted by the tool (--fit), the diagnosis runs with default options, and the
// table row says whether the documented physics is named, how many of the samples where it acts lie in
// the windows, and the validation RMSE before and after.
// Usage: diagnose_real [OUT_DIR] [NAME] [--settings]   (defaults: diagnose_real_out, all; NAME = silverbox,
// tanks, emps or all). With --settings, each recording is also diagnosed under a grid of reasonable
// settings (nominal structures x held-out fractions x warm-up samples) and the verdicts are counted.
#include <filesystem>
#include <functional>
#include <string>

#include <fmt/format.h>

#include "core/atomic_write.hpp"
#include "diagnose/diagnose.hpp"
#include "diagnose/signal_stats.hpp"

using namespace hw::diagnose;

namespace {

struct RealCase {
  std::string name, title, physics, expected;  // expected verdict label, e.g. "cubic_stiffness@state"
  std::string acts_in;                         // per-block windows compared with `acts` (e.g. "... upper limit")
  std::string nominal;                         // --fit structure
  std::vector<std::string> other_nominals;     // further reasonable structures for the settings grid
  StateVariable state = StateVariable::kPosition;
  std::size_t init_samples = 0;
  std::function<void(Recording*, Recording*)> load;
  // Samples of the identification recording where the documented physics acts (independent of the model).
  std::function<std::vector<bool>(const Recording&)> acts;
  std::string acts_text;
};

std::string SourceDir() { return HW_SOURCE_DIR; }

std::vector<bool> Where(const std::vector<double>& v, const std::function<bool(std::size_t)>& pred) {
  std::vector<bool> m(v.size());
  for (std::size_t t = 0; t < v.size(); ++t) m[t] = pred(t);
  return m;
}

std::vector<RealCase> Cases() {
  std::vector<RealCase> cs;
  {
    RealCase c;
    c.name = "silverbox";
    c.title = "Silverbox SNLS80mV (V1 -> V2)";
    c.physics = "hardening (cubic) spring of an electronic mass–spring–damper";
    c.expected = "cubic_stiffness@state";
    c.acts_in = "cubic_stiffness@state";
    c.nominal = "linear:2,3";
    c.other_nominals = {"linear:2,2", "linear:3,3", "hw:2,3,1,3"};
    c.init_samples = 50;
    c.load = [](Recording* id, Recording* va) {
      ColumnNames cols;
      cols.u = "V1";
      cols.y = "V2";
      const Recording all = ReadRecording({"/work/shared/data/silverbox/SNLS80mV.csv", cols});
      // Inside the multisine part [40650, 127400); 50 warm-up samples each.
      *id = Slice(all, 40600, 50650, "SNLS80mV.csv [40600, 50650)");
      *va = Slice(all, 105662, 115712, "SNLS80mV.csv [105662, 115712)");
    };
    c.acts = [](const Recording& r) {
      std::vector<double> a;
      for (double v : r.y) a.push_back(std::abs(v));
      const double q = Quantile(a, 0.8);
      return Where(r.y, [&](std::size_t t) { return std::abs(r.y[t]) > q; });
    };
    c.acts_text = "the 20 % largest |y| (where the cubic term of the spring force is largest)";
    cs.push_back(c);
  }
  {
    RealCase c;
    c.name = "tanks";
    c.title = "Cascaded tanks (uEst -> yEst, validation uVal -> yVal)";
    c.physics = "overflow of the lower tank (its level saturates at the top, recorded as 10 V)";
    c.expected = "state_saturation@state";
    c.acts_in = "state_saturation@state upper limit";
    c.nominal = "linear:2,2";
    c.other_nominals = {"linear:2,3", "linear:3,3", "hw:2,2,2,1", "hw:2,2,1,2", "hw:2,2,3,1"};
    c.load = [](Recording* id, Recording* va) {
      const std::string f = SourceDir() + "/paper_examples/data/cascaded_tanks/dataBenchmark.csv";
      ColumnNames e, v;
      e.u = "uEst", e.y = "yEst", v.u = "uVal", v.y = "yVal";
      *id = ReadRecording({f, e});
      *va = ReadRecording({f, v});
      id->name = "dataBenchmark.csv uEst -> yEst";
      va->name = "dataBenchmark.csv uVal -> yVal";
    };
    c.acts = [](const Recording& r) { return Where(r.y, [&](std::size_t t) { return r.y[t] >= 9.95; }); };
    c.acts_text = "samples at the overflow level (y >= 9.95 V)";
    cs.push_back(c);
  }
  {
    RealCase c;
    c.name = "emps";
    c.title = "EMPS drive (force -> velocity, 100 Hz)";
    c.physics = "Coulomb friction with asymmetric levels (plus viscous friction, which is linear)";
    c.expected = "coulomb_friction@state";
    c.acts_in = "coulomb_friction@state";
    c.nominal = "linear:1,1,1";
    c.other_nominals = {"linear:1,1,0", "linear:1,2,1", "linear:2,2,1"};
    c.state = StateVariable::kVelocity;
    c.load = [](Recording* id, Recording* va) {
      ColumnNames cols;
      cols.u = "force", cols.y = "velocity";
      const std::string d = SourceDir() + "/paper_examples/data/emps/";
      *id = ReadRecording({d + "emps_estimation_100hz.csv", cols});
      *va = ReadRecording({d + "emps_validation_100hz.csv", cols});
    };
    c.acts = [](const Recording& r) {
      // Within 0.1 s (10 samples) of a reversal of the velocity: where friction switches direction.
      std::vector<bool> m(r.y.size(), false);
      for (std::size_t t = 1; t < r.y.size(); ++t)
        if ((r.y[t] > 0) != (r.y[t - 1] > 0))
          for (std::size_t s = t > 10 ? t - 10 : 0; s < std::min(r.y.size(), t + 10); ++s) m[s] = true;
      return m;
    };
    c.acts_text = "samples within 0.1 s of a velocity reversal (where friction switches direction)";
    cs.push_back(c);
  }
  return cs;
}

struct Overlap {
  double recall = 0.0, precision = 0.0;
};

Overlap Compare(const std::vector<bool>& windows, const std::vector<bool>& acts, std::size_t skip) {
  std::size_t both = 0, nw = 0, na = 0;
  for (std::size_t t = skip; t < windows.size(); ++t) {
    both += windows[t] && acts[t];
    nw += windows[t];
    na += acts[t];
  }
  return {na ? double(both) / na : 0.0, nw ? double(both) / nw : 0.0};
}

bool Named(const std::string& label, const std::string& expected) {
  return label.rfind(expected, 0) == 0 || label.find("+" + expected) != std::string::npos;
}

// The recording under every combination of structure, held-out fraction and warm-up length.
std::string SettingsGrid(const RealCase& c, const Recording& ident, const Recording& valid) {
  std::vector<std::string> structures = {c.nominal};
  structures.insert(structures.end(), c.other_nominals.begin(), c.other_nominals.end());
  int named = 0, total = 0;
  std::string rows;
  for (const auto& structure : structures)
    for (double holdout : {1.0 / 3, 0.25})
      for (std::size_t warm : {c.init_samples, c.init_samples + 50}) {
        DiagnoseOptions o;
        o.init_samples = warm;
        o.holdout_fraction = holdout;
        o.state_variable = c.state;
        const NominalSpec spec = NominalSpec::Parse(structure);
        DiagnoseReport r;
        try {
          const NominalFit fit = FitNominal(spec, {&ident.u, &ident.y, warm, 0}, o.nominal_fit);
          Diagnose(o, fit.model, &spec, ident, valid, &r);
        } catch (const std::exception& e) {
          r.message = e.what();
        }
        const std::string label = !r.ok ? "error" : (r.verdict == Effect::kNone ? "none" : r.augmented_model.Label());
        ++total;
        named += Named(label, c.expected);
        rows += fmt::format("| `{}` | {:.2f} | {} | `{}` | {:.4g} -> {:.4g} |\n", structure, holdout, warm, label,
                            r.nominal_refit.rmse, r.augmented.rmse);
      }
  return fmt::format("#### {}: documented physics named in {} of {} settings\n\n| nominal | held-out | warm-up | "
                     "verdict | validation RMSE |\n|---|---|---|---|---|\n{}\n",
                     c.title, named, total, rows);
}

}  // namespace

int main(int argc, char** argv) {
  const std::string out = argc > 1 ? argv[1] : "diagnose_real_out";
  const std::string only = argc > 2 && std::string(argv[2]) != "all" ? argv[2] : "";
  const bool grid = argc > 3 && std::string(argv[3]) == "--settings";
  std::string settings;
  std::string md =
      "| recording | documented physics | nominal | verdict | physics named | samples where it acts inside the "
      "windows | windows hold (precision) | flagged | validation RMSE nominal refit -> augmented | fit % |\n"
      "|---|---|---|---|---|---|---|---|---|---|\n";
  std::string details;
  int failures = 0;
  for (const RealCase& c : Cases()) {
    if (!only.empty() && only != c.name) continue;
    Recording ident, valid;
    try {
      c.load(&ident, &valid);
    } catch (const std::exception& e) {
      fmt::print(stderr, "{}: {}\n", c.name, e.what());
      md += fmt::format("| {} | {} | — | not run: {} | | | | | | |\n", c.title, c.physics, e.what());
      ++failures;
      continue;
    }
    DiagnoseOptions o;
    o.init_samples = c.init_samples;
    o.state_variable = c.state;
    const NominalSpec spec = NominalSpec::Parse(c.nominal);
    const NominalFit fit = FitNominal(spec, {&ident.u, &ident.y, o.init_samples, 0}, o.nominal_fit);
    DiagnoseReport r;
    Diagnose(o, fit.model, &spec, ident, valid, &r);
    if (!r.ok) {
      fmt::print(stderr, "{}: {}\n", c.name, r.message);
      ++failures;
      continue;
    }
    WriteReport(r, ident, valid, out + "/" + c.name);
    const std::string label = r.verdict == Effect::kNone ? "none" : r.augmented_model.Label();
    const bool named = Named(label, c.expected);
    // The windows of the block (or limit) that carries the documented physics; all windows otherwise.
    std::vector<bool> windows = r.mask;
    for (const auto& w : r.block_windows)
      if (w.label == c.acts_in || (w.label == c.expected && windows == r.mask)) windows = w.mask;
    const Overlap ov = Compare(windows, c.acts(ident), o.init_samples);
    std::size_t flagged = 0;
    for (bool m : windows) flagged += m;
    std::string params;
    for (const auto& b : r.verdict_blocks) params += " (" + ParameterText(b, r.augmented_model) + ")";
    md += fmt::format("| {} | {} | `{}` | `{}`{} | {} | {:.0f} % | {:.0f} % | {:.1f} % | {:.4g} -> {:.4g} | {:.1f} -> "
                      "{:.1f} |\n",
                      c.title, c.physics, c.nominal, label, params, named ? "yes" : "**no**", 100 * ov.recall,
                      100 * ov.precision, 100.0 * flagged / r.mask.size(), r.nominal_refit.rmse, r.augmented.rmse,
                      r.nominal_refit.fit_percent, r.augmented.fit_percent);
    details += fmt::format("### {}\n\n{}\n\nWhere the physics acts: {}. {}. Report: `{}/{}/report.md`.\n\n", c.title,
                           r.message, c.acts_text, r.initial_state_note, out, c.name);
    fmt::print("{}: {} (expected {}), {:.1f} s\n", c.name, label, c.expected, r.seconds);
    if (grid) settings += SettingsGrid(c, ident, valid);
  }
  std::filesystem::create_directories(out);
  hw::write_text_atomic(out + "/real_recordings.md", md + "\n" + details + settings);
  fmt::print("{}\n{}{}", md, details, settings);
  return failures ? 1 : 0;
}
