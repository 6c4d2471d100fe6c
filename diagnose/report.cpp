// report.json, report.md and the gnuplot figures of a diagnosis.
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <sstream>

#include <fmt/format.h>

#include "core/atomic_write.hpp"
#include "core/input_error.hpp"
#include "core/output_files.hpp"
#include "diagnose/diagnose.hpp"

namespace hw::diagnose {
namespace {

using Windows = std::vector<std::pair<std::size_t, std::size_t>>;

nlohmann::json TimeWindows(const Windows& w, const std::vector<double>& t) {
  nlohmann::json j = nlohmann::json::array();
  for (const auto& [a, b] : w) j.push_back({t[a], t[b]});
  return j;
}

nlohmann::json SampleWindows(const Windows& w) {
  nlohmann::json j = nlohmann::json::array();
  for (const auto& [a, b] : w) j.push_back({a, b});
  return j;
}

std::string Verdict(const DiagnoseReport& r) {
  return r.verdict == Effect::kNone ? "none" : r.augmented_model.Label();
}

// A block's JSON plus its limits in the recording's units where they differ (a state saturation acts
// on z, which the output map and offset turn into the recorded value).
nlohmann::json BlockJson(const EffectBlock& b, const AugmentedModel& m) {
  nlohmann::json j = b.to_json();
  if (b.effect == Effect::kStateSaturation) {
    EffectBlock in_units = b;
    in_units.params = ParametersInRecordingUnits(b, m);
    j["parameters_in_recording_units"] = in_units.to_json()["parameters"];
  }
  const auto force = FrictionLevelsInInputUnits(b, m);
  if (!force.empty()) j["levels_in_input_units"] = {{"level_up", force[0]}, {"level_down", force[1]}};
  return j;
}

std::string ParamTextOf(const Finding& f) {
  std::string s;
  for (const auto& b : f.model.blocks)
    s += fmt::format("{}{} ({})", s.empty() ? "" : " + ", b.Label(), ParameterText(b, f.model));
  return s;
}

nlohmann::json StartsJson(const std::vector<NominalStart>& starts) {
  nlohmann::json j = nlohmann::json::array();
  for (const auto& s : starts) j.push_back(s.to_json());
  return j;
}

nlohmann::json FindingsJson(const std::vector<Finding>& fs) {
  nlohmann::json j = nlohmann::json::array();
  for (const auto& f : fs) j.push_back(f.to_json());
  return j;
}

// Plot data: one whitespace-separated file, '#' header so gnuplot skips it.
void WriteSeries(const std::string& path, const std::vector<std::string>& names,
                 const std::vector<const std::vector<double>*>& cols) {
  std::ostringstream s;
  s << "#";
  for (const auto& n : names) s << " " << n;
  s << "\n";
  const std::size_t n = cols.front()->size();
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t c = 0; c < cols.size(); ++c) s << (c ? " " : "") << fmt::format("{:.9g}", (*cols[c])[i]);
    s << "\n";
  }
  write_text_atomic(path, s.str());
}

std::string ShadeWindows(const Windows& w, const std::vector<double>& t) {
  std::string s = "unset object\n";
  const std::size_t limit = 400;  // gnuplot objects; enough for a readable figure
  for (std::size_t i = 0; i < w.size() && i < limit; ++i)
    s += fmt::format("set object {} rect from {:.9g}, graph 0 to {:.9g}, graph 1 behind fc rgb '#ffd8a8' fs solid 0.6 noborder\n",
                     i + 1, t[w[i].first], t[w[i].second] + (t.size() > 1 ? t[1] - t[0] : 1.0));
  return s;
}

}  // namespace

nlohmann::json Finding::to_json() const {
  nlohmann::json bl = nlohmann::json::array();
  for (const auto& b : model.blocks) bl.push_back(BlockJson(b, model));
  const auto first = bl.empty() ? nlohmann::json::object() : bl.front();
  return {{"label", Label()},
          {"effect", first.value("effect", "none")},
          {"location", first.value("location", "")},
          {"parameters", first.value("parameters", nlohmann::json::object())},
          {"blocks", bl},
          {"score", score},
          {"eligible", eligible},
          {"evidence",
           {{"text", evidence},
            {"holdout", holdout.to_json()},
            {"validation", validation.to_json()},
            {"swapped", swapped_tested ? swapped.to_json() : nlohmann::json(nullptr)},
            {"extra_parameters", extra_parameters},
            {"share_of_improvement_in_residual_windows", in_window_share}}}};
}

nlohmann::json ReportJson(const DiagnoseReport& r, const Recording& ident, const Recording& valid) {
  std::size_t flagged = 0;
  for (bool m : r.mask) flagged += m;
  nlohmann::json verdict_blocks = nlohmann::json::array();
  for (const auto& b : r.verdict_blocks) verdict_blocks.push_back(BlockJson(b, r.augmented_model));
  nlohmann::json j;
  j["tool"] = "hwbounds diagnose";
  j["schema_version"] = 2;
  j["ok"] = r.ok;
  j["verdict"] = EffectName(r.verdict);
  j["verdict_location"] = r.verdict == Effect::kNone ? nlohmann::json(nullptr) : nlohmann::json(LocationName(r.verdict_location));
  j["verdict_blocks"] = verdict_blocks;
  j["summary"] = r.message;
  j["baseline"] = {{"source", r.baseline_source}, {"starts", StartsJson(r.baseline_starts)},
                   {"initial_state", r.initial_state_note},
                   {"holdout_rmse", r.baseline_holdout_rmse},
                   {"nominal_status", NominalStatusName(r.nominal_status)},
                   {"nominal_status_note", r.nominal_status_note},
                   {"richer_nominal", r.richer_note}};
  j["operating_point"] = r.operating_point.to_json();
  j["feedback"] = r.feedback.to_json();
  j["findings"] = FindingsJson(r.findings);
  j["pairs"] = FindingsJson(r.pairs);
  j["mismatch"] = {
      {"source", r.mask_source},
      {"windows", TimeWindows(r.windows, ident.t)},
      {"window_samples", SampleWindows(r.windows)},
      {"flagged_fraction", r.mask.empty() ? 0.0 : double(flagged) / r.mask.size()},
      {"validation_windows", TimeWindows(r.validation_windows, valid.t)},
      {"nominal_residual_windows", SampleWindows(MaskToWindows(r.residual_mask))},
      {"per_block", [&] {
         nlohmann::json pb = nlohmann::json::array();
         for (const auto& w : r.block_windows)
           pb.push_back({{"label", w.label}, {"flagged_fraction", w.fraction},
                         {"window_samples", SampleWindows(MaskToWindows(w.mask))}});
         return pb;
       }()},
      {"region", r.region.to_json()},
      {"noise_std", r.noise_std},
      {"noise_std_source", r.noise_estimated ? "estimated (1.4826 MAD of residual differences / sqrt 2, capped by the "
                                               "best model's RMS error)"
                                             : "given"}};
  nlohmann::json aug = r.augmented.to_json();
  aug["model"] = r.augmented_model.Label();
  j["fit"] = {{"nominal", r.nominal.to_json()},
              {"nominal_refit", r.nominal_refit.to_json()},
              {"augmented", aug},
              {"on", "validation recording (initial state re-estimated for each model)"},
              {"validation_paired_z", r.validation_z},
              {"nominal_parameters_off", r.parameters_off},
              {"nominal_refit_paired_z", r.refit_z},
              {"note", r.validation_note},
              {"identification", {{"nominal", r.ident_nominal.to_json()}, {"augmented", r.ident_augmented.to_json()}}}};
  j["residual_tests"] = {
      {"nominal_on_identification",
       {{"whiteness", r.whiteness_nominal.to_json()}, {"input_cross_correlation", r.input_corr_nominal.to_json()}}},
      {"augmented_on_validation",
       {{"whiteness", r.whiteness_augmented.to_json()}, {"input_cross_correlation", r.input_corr_augmented.to_json()}}}};
  j["models"] = {{"nominal", r.nominal_model.to_json()},
                 {"nominal_refit", r.nominal_refit_model.to_json()},
                 {"augmented", r.augmented_model.to_json()}};
  j["data"] = {{"identification", {{"name", ident.name}, {"samples", ident.y.size()}}},
               {"validation", {{"name", valid.name}, {"samples", valid.y.size()}}}};
  j["run_time_seconds"] = r.seconds;
  return j;
}

std::string ReportMarkdown(const DiagnoseReport& r, const Recording& ident, const Recording& valid) {
  std::string s = "# Discrepancy diagnosis\n\n";
  // The message starts with "verdict: " and names the blocks with their parameters once.
  s += fmt::format("**Verdict:** {}\n\n", r.message.substr(r.message.find(' ') + 1));
  s += fmt::format("Identification: `{}` ({} samples); validation: `{}` ({} samples). Run time {:.2f} s.\n\n",
                   ident.name, ident.y.size(), valid.name, valid.y.size(), r.seconds);
  s += "## Where the nominal model differs\n\n";
  s += fmt::format("Noise standard deviation {:.4g} ({}). {} window(s) of {}; they are characterised by: **{}**.\n\n",
                   r.noise_std, r.noise_estimated ? "estimated from the residual" : "given", r.windows.size(),
                   r.mask_source, r.region.description);
  if (!r.windows.empty()) {
    s += "First windows (t_start – t_end): ";
    for (std::size_t i = 0; i < r.windows.size() && i < 12; ++i)
      s += fmt::format("{}[{:.6g}, {:.6g}]", i ? ", " : "", ident.t[r.windows[i].first], ident.t[r.windows[i].second]);
    s += r.windows.size() > 12 ? ", …\n\n" : "\n\n";
  }
  auto test_row = [](const std::string& name, const CorrelationTest& t) {
    return fmt::format("| {} | {:.1f} | {} | {:.1f} | {} |\n", name, t.statistic, t.dof, t.threshold,
                       t.passed ? "pass" : "fail");
  };
  s += "Residual tests (Ljung): N·Σρ² against the χ² 99 % quantile.\n\n| test | statistic | dof | threshold | result |\n|---|---|---|---|---|\n";
  s += test_row("nominal, identification: whiteness", r.whiteness_nominal);
  s += test_row("nominal, identification: cross-correlation with u", r.input_corr_nominal);
  s += test_row("augmented, validation: whiteness", r.whiteness_augmented);
  s += test_row("augmented, validation: cross-correlation with u", r.input_corr_augmented);
  s += fmt::format("\n## Baseline\n\nThe nominal model refitted alone: {}. {}.\n\n| start | fit RMSE | held-out RMSE |\n|---|---|---|\n",
                   r.baseline_source, r.initial_state_note);
  for (const auto& st : r.baseline_starts)
    s += fmt::format("| {} | {:.5g} | {:.5g} |\n", st.name, st.fit_rmse, st.holdout_rmse);
  auto table = [&](const std::vector<Finding>& fs) {
    std::string t = "| rank | blocks | held-out MSE ratio | z | validation MSE ratio | z | score | eligible |\n";
    t += "|---|---|---|---|---|---|---|---|\n";
    int rank = 0;
    for (const auto& f : fs)
      t += fmt::format("| {} | {} | {:.3f} | {:.1f} | {:.3f} | {:.1f} | {:.3f} | {} |\n", ++rank, ParamTextOf(f),
                       f.holdout.ratio, f.holdout.z, f.validation.ratio, f.validation.z, f.score,
                       f.eligible ? "yes" : "no");
    return t;
  };
  s += "\n## Candidate effects\n\nEach block is fitted on the first part of the identification recording, scored on "
       "its held-out tail, refitted on the whole recording and scored on the validation recording (ratios to the "
       "baseline; score = 1 - geometric mean of the penalised ratios).\n\n";
  s += table(r.findings);
  if (!r.pairs.empty()) s += "\n### Combinations with the best block (ratios to that block alone)\n\n" + table(r.pairs);
  s += fmt::format("\n{}\n\n## Fit on the validation recording\n\n", r.validation_note);
  s += "| model | RMSE | fit % |\n|---|---|---|\n";
  s += fmt::format("| nominal (as given / fitted) | {:.5g} | {:.2f} |\n", r.nominal.rmse, r.nominal.fit_percent);
  s += fmt::format("| nominal, linear part refitted | {:.5g} | {:.2f} |\n", r.nominal_refit.rmse, r.nominal_refit.fit_percent);
  s += fmt::format("| augmented ({}) | {:.5g} | {:.2f} |\n\n", r.augmented_model.Label(), r.augmented.rmse,
                   r.augmented.fit_percent);
  s += "## Figures\n\n![identification](identification.png)\n\n![validation](validation.png)\n\n"
       "![residual against the operating condition](residual_vs_condition.png)\n\n![residual in time](residual_time.png)\n";
  return s;
}

std::vector<std::string> WriteReport(const DiagnoseReport& r, const Recording& ident, const Recording& valid,
                                     const std::string& dir) {
  namespace fs = std::filesystem;
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) throw InputError(fmt::format("{}: cannot create output directory: {}", dir, ec.message()));
  std::vector<std::string> written;
  auto put = [&](const std::string& name, const std::string& text) {
    write_text_atomic((fs::path(dir) / name).string(), text);
    written.push_back((fs::path(dir) / name).string());
  };
  put("report.json", ReportJson(r, ident, valid).dump(2) + "\n");
  put("report.md", ReportMarkdown(r, ident, valid));
  put("nominal_model.json", r.nominal_model.to_json().dump(2) + "\n");
  put("augmented_model.json", r.augmented_model.to_json().dump(2) + "\n");
  if (!r.ok) return written;

  // Plot data.
  std::vector<double> e_nom(ident.y.size()), e_aug(ident.y.size());
  for (std::size_t t = 0; t < ident.y.size(); ++t) {
    e_nom[t] = ident.y[t] - r.ident_nominal_sim[t];
    e_aug[t] = ident.y[t] - r.ident_augmented_sim[t];
  }
  const std::string p_ident = (fs::path(dir) / "identification.dat").string();
  WriteSeries(p_ident, {"t", "y", "nominal", "augmented", "residual_nominal", "residual_augmented"},
              {&ident.t, &ident.y, &r.ident_nominal_sim, &r.ident_augmented_sim, &e_nom, &e_aug});
  const std::string p_valid = (fs::path(dir) / "validation.dat").string();
  WriteSeries(p_valid, {"t", "y", "nominal", "augmented"},
              {&valid.t, &valid.y, &r.valid_nominal_sim, &r.valid_augmented_sim});
  written.push_back(p_ident);
  written.push_back(p_valid);
  const Condition* cond = nullptr;
  for (const auto& c : r.conditions)
    if (c.name == (r.region.found ? r.region.condition : std::string("u"))) cond = &c;
  if (cond) {
    const std::string p = (fs::path(dir) / "condition.dat").string();
    WriteSeries(p, {cond->name, "residual_nominal", "residual_augmented"}, {&cond->values, &e_nom, &e_aug});
    written.push_back(p);
  }
  const std::string verdict = Verdict(r);
  const std::string shade = r.verdict == Effect::kNone ? "residual beyond the noise" : "where the verdict acts";
  std::string gp = "set terminal pngcairo size 1200,500 noenhanced\nset grid\nset key outside top center horizontal\n";
  gp += ShadeWindows(r.windows, ident.t);
  gp += fmt::format(
      "set output 'identification.png'\nset title 'Identification: y and simulations, augmented = {}; shaded = {}'\nset xlabel 't'\nset ylabel 'y'\n"
      "plot 'identification.dat' u 1:2 w l lc rgb '#999999' t 'y measured', '' u 1:3 w l lw 1.5 lc rgb '#d62728' t "
      "'nominal', '' u 1:4 w l lw 1.5 lc rgb '#1f77b4' t 'augmented'\n",
      verdict, shade);
  gp += fmt::format(
      "set output 'residual_time.png'\nset title 'Simulation error on the identification recording (±3 sigma "
      "noise band)'\nset ylabel 'y - yhat'\nplot 'identification.dat' u 1:5 w l lc rgb '#d62728' t 'nominal', '' u "
      "1:6 w l lc rgb '#1f77b4' t 'augmented', {0:.9g} w l dt 2 lc rgb 'black' t '+3 sigma', -{0:.9g} w l dt 2 lc "
      "rgb 'black' t '-3 sigma'\n",
      3 * r.noise_std);
  gp += ShadeWindows(r.validation_windows, valid.t);
  gp += "set output 'validation.png'\nset title 'Validation: y and simulations; shaded = " + shade + "'\nset ylabel 'y'\n"
        "plot 'validation.dat' u 1:2 w l lc rgb '#999999' t 'y measured', '' u 1:3 w l lw 1.5 lc rgb '#d62728' t "
        "'nominal', '' u 1:4 w l lw 1.5 lc rgb '#1f77b4' t 'augmented'\n";
  if (cond) {
    gp += "unset object\n";
    gp += fmt::format(
        "set output 'residual_vs_condition.png'\nset title 'Simulation error against {} (region: {})'\n"
        "set xlabel '{}'\nset ylabel 'y - yhat'\n{}plot 'condition.dat' u 1:2 w p pt 7 ps 0.4 lc rgb '#d62728' t "
        "'nominal', '' u 1:3 w p pt 7 ps 0.4 lc rgb '#1f77b4' t 'augmented'\n",
        cond->words, r.region.found ? r.region.relation + " " + fmt::format("{:.4g}", r.region.threshold) : "none",
        cond->words, r.region.found ? fmt::format("set arrow from {0:.9g}, graph 0 to {0:.9g}, graph 1 nohead dt 2\n", r.region.threshold) : "");
  }
  put("plots.gp", gp);
  if (RunGnuplot(dir, "plots.gp").empty()) {
    for (const char* f : {"identification.png", "residual_time.png", "validation.png", "residual_vs_condition.png"})
      if (fs::exists(fs::path(dir) / f)) written.push_back((fs::path(dir) / f).string());
  }
  return written;
}

}  // namespace hw::diagnose
