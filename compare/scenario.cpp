#include "compare/scenario.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <fmt/format.h>

#include "core/input_error.hpp"
#include "core/json_input.hpp"
#include "dss/basis.hpp"
#include "dss/set_membership.hpp"
#include "estimators/esmaeilani/valve_case.hpp"
#include "sdp/sdp_solver.hpp"

namespace hw::compare {
namespace {

void ReadHold(const nlohmann::json& j, const std::string& where, int* lo, int* hi) {
  if (!j.contains("hold")) return;
  const auto h = j.at("hold").get<std::vector<int>>();
  if (h.size() != 2) throw InputError(where + ".hold: expected [min, max] samples");
  *lo = h[0];
  *hi = h[1];
}

const char* kSetMembershipExample = R"({
  "name": "setmembership-example",
  "description": "Paper 001 Section VI: x = u + 0.4u^2 - 0.1u^3, z_t = -1.8z_{t-1} - 0.9z_{t-2} + 1.6x_{t-1} + 2.1x_{t-2}, z = w + 0.8w^2 + 3.2w^3, u uniform in [-10, 10], bounded uniform output noise at 31 dB",
  "plant": "hw",
  "model": {"type": "hammerstein_wiener", "name": "cerone_example",
            "input_nonlinearity": {"kind": "polynomial", "coefficients": [1, 0.4, -0.1]},
            "linear": {"a": [1.8, 0.9], "b": [0, 1.6, 2.1], "delay": 0},
            "output_nonlinearity": {"kind": "identity"}},
  "output_inverse_polynomial": [1, 0.8, 3.2],
  "input_range": [-10, 10],
  "noise": {"snr_db": 31},
  "setmembership": {"samples": 300, "horizon": 2, "order": 2, "box": 10},
  "esmaeilani": {"segments": 2, "samples": 300, "hold": [3, 15], "grid_f": 12, "grid_g": 12},
  "validation": {"samples": 500, "hold": [1, 10]}
})";

const char* kBrouriBacklash = R"({
  "name": "brouri-backlash",
  "description": "Paper 000 Section 6: backlash (S = 1, d+ = 0.5, d- = -0.5) -> G(s) = 0.2/((s+0.5)(s+0.2)) -> h = 0.2x^5 - 0.42x^3 + 0.25x, Gaussian noise sigma = 0.01, steps then sines through the pre-compensator",
  "plant": "backlash",
  "noise": {"std": 0.01},
  "brouri": {"periods": 50, "samples_per_period": 512}
})";

const char* kValve = R"({
  "name": "valve",
  "description": "Paper 002 pressure-control valve rebuilt in simulation: dead band f = min(u, 80), third-order linear block of the paper, saturating output g, closing operations from the fully open state, output noise std 0.3 %",
  "plant": "valve",
  "esmaeilani": {"segments": 4, "samples": 400},
  "validation": {"samples": 400}
})";

}  // namespace

const char* ToString(PlantKind k) {
  switch (k) {
    case PlantKind::kDiscreteHw: return "hw";
    case PlantKind::kValve: return "valve";
    case PlantKind::kBacklash: return "backlash";
  }
  return "?";
}

bool Scenario::IsValid(std::string* error) const {
  auto fail = [&](std::string m) {
    if (error) *error = std::move(m);
    return false;
  };
  if (name.empty()) return fail("scenario needs a name");
  if (!(input_lo < input_hi)) return fail("input_range must be [lo, hi] with lo < hi");
  if (kind == PlantKind::kDiscreteHw) {
    std::string e;
    if (!plant.model.IsValid(&e)) return fail("model: " + e);
    if (!(noise_bound > 0) && !(snr_db > 0 && std::isfinite(snr_db)))
      return fail("noise: give a positive {\"snr_db\": ...} or {\"bound\": ...}");
    if (!plant.inverse_output.empty() && plant.inverse_output[0] == 0.0)
      return fail("output_inverse_polynomial: the linear coefficient must be nonzero (it is normalised to 1)");
  }
  if (kind == PlantKind::kBacklash) {
    std::string e;
    if (!backlash.IsValid(&e)) return fail("system: " + e);
  }
  const auto& sm = setmembership;
  if (sm.samples < 10 || !(sm.box_half_width > 0)) return fail("setmembership: samples >= 10, box > 0");
  std::string e;  // the bounds command's checks, with its messages
  if (!dss::ValidHorizon(sm.horizon, &e) || !dss::ValidOrder(sm.order, sm.horizon, &e) ||
      !dss::ValidBoundsSolver(sm.solver, &e) || !dss::ValidContractionPasses(sm.contract_passes, &e))
    return fail("setmembership: " + e);
  const auto& es = esmaeilani;
  if (es.segments < 1 || es.samples < 20 || es.hold_min < 1 || es.hold_max < es.hold_min || es.grid_f < 2 ||
      es.grid_g < 2 || es.max_iterations < 1)
    return fail("esmaeilani: segments >= 1, samples >= 20, 1 <= hold min <= hold max, grids >= 2, max_iterations >= 1");
  if (validation.samples < 20 || validation.hold_min < 1 || validation.hold_max < validation.hold_min)
    return fail("validation: samples >= 20 and 1 <= hold min <= hold max");
  if (brouri.periods < 1 || brouri.samples_per_period < 16) return fail("brouri: periods >= 1, samples_per_period >= 16");
  for (double w : brouri.omegas)
    if (!(w > 0)) return fail("brouri.omegas must be positive");
  return true;
}

nlohmann::json Scenario::to_json() const {
  nlohmann::json j = {{"name", name}, {"description", description}, {"plant", ToString(kind)},
                      {"input_range", {input_lo, input_hi}}};
  if (kind == PlantKind::kDiscreteHw || kind == PlantKind::kValve) {
    j["model"] = plant.model.to_json();
    if (!plant.inverse_output.empty()) j["output_inverse_polynomial"] = plant.inverse_output;
  }
  if (kind == PlantKind::kDiscreteHw)
    j["noise"] = noise_bound > 0 ? nlohmann::json{{"bound", noise_bound}} : nlohmann::json{{"snr_db", snr_db}};
  if (kind == PlantKind::kBacklash) {
    j["system"] = backlash.to_json();
    j["noise"] = {{"std", backlash.noise_std}};
  }
  const auto& sm = setmembership;
  j["setmembership"] = {{"samples", sm.samples}, {"horizon", sm.horizon}, {"order", sm.order},
                        {"parameters", sm.parameters}, {"solver", sm.solver},
                        {"contract_passes", sm.contract_passes}};
  if (sm.box.empty()) j["setmembership"]["box"] = sm.box_half_width;
  else j["setmembership"]["box"] = sm.box;
  const auto& es = esmaeilani;
  j["esmaeilani"] = {{"segments", es.segments}, {"samples", es.samples}, {"hold", {es.hold_min, es.hold_max}},
                     {"grid_f", es.grid_f}, {"grid_g", es.grid_g}, {"max_iterations", es.max_iterations}};
  j["validation"] = {{"samples", validation.samples}, {"hold", {validation.hold_min, validation.hold_max}}};
  j["brouri"] = {{"periods", brouri.periods}, {"samples_per_period", brouri.samples_per_period},
                 {"omegas", brouri.omegas}};
  return j;
}

Scenario Scenario::FromJson(const nlohmann::json& j, const std::string& source) {
  Scenario s;
  try {
    CheckKeys(j, {"name", "description", "plant", "model", "model_file", "output_inverse_polynomial", "system",
                  "input_range", "noise", "setmembership", "esmaeilani", "validation", "brouri"},
              source);
    s.name = j.value("name", "");
    s.description = j.value("description", "");
    const std::string plant = j.value("plant", "hw");
    if (plant == "hw") {
      s.kind = PlantKind::kDiscreteHw;
      if (j.contains("model")) {
        try {
          s.plant.model = HwModel::from_json(j.at("model"));
        } catch (const InputError& e) {
          throw InputError(fmt::format("{}: model: {}", source, e.what()));
        }
      } else if (j.contains("model_file")) {
        auto path = std::filesystem::path(j.at("model_file").get<std::string>());
        if (path.is_relative()) path = std::filesystem::path(source).parent_path() / path;
        s.plant.model = HwModel::load(path.string());
      } else {
        throw InputError(source + ": plant \"hw\" needs \"model\" (project model JSON) or \"model_file\"");
      }
      if (j.contains("output_inverse_polynomial"))
        s.plant.inverse_output = j.at("output_inverse_polynomial").get<std::vector<double>>();
    } else if (plant == "backlash") {
      s.kind = PlantKind::kBacklash;
      try {
        s.backlash = j.contains("system") ? brouri::BacklashHwSystem::from_json(j.at("system"))
                                          : brouri::BacklashHwSystem::PaperExample();
      } catch (const InputError& e) {
        throw InputError(fmt::format("{}: system: {}", source, e.what()));
      }
    } else if (plant == "valve") {
      s.kind = PlantKind::kValve;
      esmaeilani::ValveCase valve;
      s.plant.model = valve.TrueModel(201).ToHwModel(true);
      s.plant.model.name = "valve_truth";
      s.input_lo = 0.0;
      s.input_hi = 100.0;
    } else {
      throw InputError(fmt::format("{}: plant '{}' unknown; expected hw, backlash or valve", source, plant));
    }
    if (j.contains("input_range")) {
      const auto r = j.at("input_range").get<std::vector<double>>();
      if (r.size() != 2) throw InputError(source + ": input_range must be [lo, hi]");
      s.input_lo = r[0];
      s.input_hi = r[1];
    }
    if (j.contains("noise")) {
      const auto& n = j.at("noise");
      CheckKeys(n, {"snr_db", "bound", "std"}, source + ": noise");
      if (s.kind == PlantKind::kDiscreteHw) {
        if (n.contains("std"))
          throw InputError(source + ": noise.std is Gaussian; plant \"hw\" needs bounded noise: snr_db or bound");
        if (n.contains("bound")) s.noise_bound = n.at("bound").get<double>();
        if (n.contains("snr_db")) s.snr_db = n.at("snr_db").get<double>();
      } else if (s.kind == PlantKind::kBacklash) {
        if (!n.contains("std")) throw InputError(source + ": plant \"backlash\" takes noise {\"std\": sigma}");
        s.backlash.noise_std = n.at("std").get<double>();
      } else {
        throw InputError(source + ": the valve plant uses the paper-002 case's own noise; remove \"noise\"");
      }
    }
    if (j.contains("setmembership")) {
      const auto& m = j.at("setmembership");
      const std::string w = source + ": setmembership";
      CheckKeys(m, {"samples", "horizon", "order", "parameters", "box", "solver", "contract_passes"}, w);
      auto& sm = s.setmembership;
      sm.samples = m.value("samples", sm.samples);
      sm.horizon = m.value("horizon", sm.horizon);
      sm.order = m.value("order", sm.order);
      sm.solver = m.value("solver", sm.solver);
      sm.contract_passes = m.value("contract_passes", sm.contract_passes);
      if (m.contains("parameters")) sm.parameters = m.at("parameters").get<std::vector<std::string>>();
      if (m.contains("box")) {
        if (m.at("box").is_number()) sm.box_half_width = m.at("box").get<double>();
        else sm.box = m.at("box").get<std::vector<std::pair<double, double>>>();
      }
    }
    if (j.contains("esmaeilani")) {
      const auto& m = j.at("esmaeilani");
      const std::string w = source + ": esmaeilani";
      CheckKeys(m, {"segments", "samples", "hold", "grid_f", "grid_g", "max_iterations"}, w);
      auto& es = s.esmaeilani;
      es.segments = m.value("segments", es.segments);
      es.samples = m.value("samples", es.samples);
      ReadHold(m, w, &es.hold_min, &es.hold_max);
      es.grid_f = m.value("grid_f", es.grid_f);
      es.grid_g = m.value("grid_g", es.grid_g);
      es.max_iterations = m.value("max_iterations", es.max_iterations);
    }
    if (j.contains("validation")) {
      const auto& m = j.at("validation");
      const std::string w = source + ": validation";
      CheckKeys(m, {"samples", "hold"}, w);
      s.validation.samples = m.value("samples", s.validation.samples);
      ReadHold(m, w, &s.validation.hold_min, &s.validation.hold_max);
    }
    if (j.contains("brouri")) {
      const auto& m = j.at("brouri");
      CheckKeys(m, {"periods", "samples_per_period", "omegas"}, source + ": brouri");
      s.brouri.periods = m.value("periods", s.brouri.periods);
      s.brouri.samples_per_period = m.value("samples_per_period", s.brouri.samples_per_period);
      if (m.contains("omegas")) s.brouri.omegas = m.at("omegas").get<std::vector<double>>();
    }
  } catch (const nlohmann::json::exception& e) {
    throw InputError(fmt::format("{}: {}", source, e.what()));
  }
  std::string err;
  if (!s.IsValid(&err)) throw InputError(fmt::format("{}: {}", source, err));
  return s;
}

std::vector<std::string> BuiltinScenarioNames() { return {"setmembership-example", "brouri-backlash", "valve"}; }

Scenario LoadScenario(const std::string& name_or_path) {
  if (name_or_path == "setmembership-example" || name_or_path == "cerone")
    return Scenario::FromJson(nlohmann::json::parse(kSetMembershipExample), "built-in setmembership-example");
  if (name_or_path == "brouri-backlash")
    return Scenario::FromJson(nlohmann::json::parse(kBrouriBacklash), "built-in brouri-backlash");
  if (name_or_path == "valve") return Scenario::FromJson(nlohmann::json::parse(kValve), "built-in valve");
  if (!std::filesystem::exists(name_or_path))
    throw InputError(fmt::format("--scenario '{}': neither a built-in scenario ({}) nor an existing JSON file",
                                 name_or_path, fmt::join(BuiltinScenarioNames(), ", ")));
  const nlohmann::json j = ReadJsonFile(name_or_path, "scenario JSON file");
  return Scenario::FromJson(j, name_or_path);
}

SetMembershipClass SetMembershipTruth(const Plant& plant) {
  SetMembershipClass c;
  const auto& m = plant.model;
  std::vector<double> in, inv;
  if (m.input.kind == StaticMap::Kind::kIdentity) in = {1.0};
  else if (m.input.kind == StaticMap::Kind::kPolynomial) in = m.input.coefficients;
  else {
    c.reason = "the input map is piecewise linear; paper 001's class needs a finite basis (here: powers of u)";
    return c;
  }
  if (!plant.inverse_output.empty()) inv = plant.inverse_output;
  else if (m.output.kind == StaticMap::Kind::kIdentity) inv = {1.0};
  else if (m.output.kind == StaticMap::Kind::kPolynomial && m.output.coefficients.size() == 1 &&
           m.output.coefficients[0] != 0.0)
    inv = {1.0 / m.output.coefficients[0]};
  else {
    c.reason = "the output map is not given by a polynomial inverse (output_inverse_polynomial); paper 001 bounds "
               "the inverse output map in a basis";
    return c;
  }
  if (in[0] == 0.0 || inv[0] == 0.0) {
    c.reason = "the linear coefficient of the input map or of the inverse output map is zero: gamma_1 = alpha_1 = 1 "
               "cannot normalise it";
    return c;
  }
  if (m.linear.a.empty()) {
    c.reason = "the linear block has no denominator (na = 0)";
    return c;
  }
  std::vector<double> lag(m.linear.delay + m.linear.b.size(), 0.0);
  for (std::size_t j = 0; j < m.linear.b.size(); ++j) lag[m.linear.delay + j] = m.linear.b[j];
  auto& st = c.structure;
  for (std::size_t k = 1; k <= in.size(); ++k) st.input_basis.push_back(dss::power_basis(static_cast<int>(k)));
  for (std::size_t k = 1; k <= inv.size(); ++k) st.output_basis.push_back(dss::power_basis(static_cast<int>(k)));
  st.na = static_cast<int>(m.linear.a.size());
  st.strictly_proper = lag[0] == 0.0;
  st.nb = std::max<int>(1, static_cast<int>(lag.size()) - 1);
  lag.resize(st.nb + 1, 0.0);
  std::string err;
  if (!st.IsValid(&err)) {
    c.reason = "structure: " + err;
    return c;
  }
  const auto layout = dss::MakeLayout(st);
  c.names = layout.names;
  c.theta.assign(layout.count(), 0.0);
  for (int k = 0; k < layout.num_gamma; ++k) c.theta[layout.gamma_begin + k] = in[k + 1] / in[0];
  for (int k = 0; k < layout.num_alpha; ++k) c.theta[layout.alpha_begin + k] = inv[k + 1] / inv[0];
  for (int i = 0; i < st.na; ++i) c.theta[layout.a_begin + i] = m.linear.a[i];
  const int j0 = st.strictly_proper ? 1 : 0;
  for (int j = j0; j <= st.nb; ++j) c.theta[layout.b_begin + j - j0] = lag[j] * in[0] / inv[0];
  c.ok = true;
  return c;
}

namespace {
bool plant_inverse_ok(const Plant& p, double zlo, double zhi) {
  const int n = 401;
  double prev = 0.0, sign = 0.0;
  for (int i = 0; i < n; ++i) {
    const double z = zlo + (zhi - zlo) * i / (n - 1);
    const auto w = p.output(z);
    if (!w) return false;
    if (i > 0) {
      const double d = *w - prev;
      // Flat pieces (saturation) are allowed; a change of direction is not.
      if (sign == 0.0 && d != 0.0) sign = d > 0 ? 1.0 : -1.0;
      if (d * sign < 0) return false;
    }
    prev = *w;
  }
  return true;
}
// Esmaeilani identifies g^-1 as ordered pairs: the output map must be monotone over the outputs the
// experiments reach (checked on the z range of a random-level record of the input range).
std::string OutputNotInvertible(const Scenario& s) {
  const auto& m = s.plant.model;
  std::vector<double> u(2000);
  for (int t = 0; t < 2000; ++t) u[t] = s.input_lo + (s.input_hi - s.input_lo) * ((t / 7) * 7919 % 1000) / 999.0;
  std::vector<double> x(u.size());
  for (std::size_t t = 0; t < u.size(); ++t) x[t] = m.input(u[t]);
  const auto z = m.linear.simulate(x);
  const auto [zlo, zhi] = std::minmax_element(z.begin(), z.end());
  if (!plant_inverse_ok(s.plant, *zlo, *zhi))
    return "the output map is not monotone over the reachable outputs: Esmaeilani's ordered pairs of g^-1 "
           "cannot represent it";
  return "";
}
}  // namespace

const std::vector<std::string>& AllMethods() {
  static const std::vector<std::string> m = {"setmembership", "exact", "brouri", "esmaeilani"};
  return m;
}

Applicability MethodApplies(const Scenario& s, const std::string& method) {
  Applicability a;
  if (method == "exact") {  // the exact set D: the same model class and record, after the D^ss(n) run
    a = MethodApplies(s, "setmembership");
    if (a.applies)
      a.experiment += "; the exact set D bounded inside the D^ss(n) box (assumes the inverse output map increases "
                      "on the data range)";
    return a;
  }
  if (method == "setmembership") {
    if (s.kind == PlantKind::kBacklash) {
      a.reason = "the plant has a backlash (a memory operator, not a static map) and a non-invertible output "
                 "polynomial h: outside paper 001's model class, so its intervals would not be guarantees";
    } else if (s.kind == PlantKind::kValve) {
      a.reason = "the valve's dead band (kink at 80 %) is no finite polynomial and its saturating output map has "
                 "no inverse: outside paper 001's model class, so its intervals would not be guarantees";
    } else {
      const auto c = SetMembershipTruth(s.plant);
      if (!c.ok) a.reason = c.reason;
      a.applies = c.ok;
      a.experiment = fmt::format("{} samples of random input uniform in [{}, {}], bounded uniform output noise",
                                 s.setmembership.samples, s.input_lo, s.input_hi);
    }
  } else if (method == "brouri") {
    if (s.kind != PlantKind::kBacklash) {
      a.reason = "Brouri's method needs a continuous-time plant with a backlash input operator (steps that reveal "
                 "the backlash borders, then sines through its inverse); this plant has a static input map";
    } else {
      a.applies = true;
      a.experiment = "the paper's steps (reset, ascending, descending holds) then sines through the estimated "
                     "backlash-inverse pre-compensator";
    }
  } else if (method == "esmaeilani") {
    if (s.kind == PlantKind::kBacklash) {
      a.reason = "the plant's input nonlinearity is a backlash (memory) and its output polynomial h is not "
                 "invertible: Esmaeilani's static f and ordered pairs of g^-1 cannot represent it";
    } else if (s.kind == PlantKind::kValve) {
      a.applies = true;
      a.experiment = fmt::format("{} closing operations of {} samples (paper 002's valve case)", s.esmaeilani.segments,
                                 s.esmaeilani.samples);
    } else if (const std::string why = OutputNotInvertible(s); !why.empty()) {
      a.reason = why;
    } else {
      a.applies = true;
      a.experiment = fmt::format("{} operating records of {} samples (random levels held {}..{} samples)",
                                 s.esmaeilani.segments, s.esmaeilani.samples, s.esmaeilani.hold_min,
                                 s.esmaeilani.hold_max);
    }
  } else {
    throw InputError(fmt::format("method '{}' unknown; expected setmembership, brouri or esmaeilani", method));
  }
  return a;
}

}  // namespace hw::compare
