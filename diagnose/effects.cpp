#include "diagnose/effects.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "core/csv_table.hpp"

namespace hw::diagnose {
namespace {

struct EffectInfo {
  Effect effect;
  const char* name;
  std::vector<const char*> params;
};

const std::vector<EffectInfo>& Infos() {
  static const std::vector<EffectInfo> infos = {
      {Effect::kBacklash, "backlash", {"half_width"}},
      {Effect::kDeadzone, "deadzone", {"half_width"}},
      {Effect::kSaturation, "saturation", {"lower", "upper"}},
      {Effect::kRateLimit, "rate_limit", {"max_step"}},
      {Effect::kDelay, "delay", {"samples"}},
      {Effect::kQuantization, "quantization", {"step"}},
      {Effect::kCoulombFriction, "coulomb_friction", {"fc"}},
      {Effect::kHysteresis, "hysteresis", {"threshold", "height"}},
      {Effect::kCubicStiffness, "cubic_stiffness", {"k3"}},
      {Effect::kStateSaturation, "state_saturation", {"lower", "upper"}},
      {Effect::kNone, "none", {}},
  };
  return infos;
}

const EffectInfo& Info(Effect e) {
  for (const auto& i : Infos())
    if (i.effect == e) return i;
  return Infos().back();
}

double Sign(double v) { return v > 0 ? 1.0 : (v < 0 ? -1.0 : 0.0); }

}  // namespace

std::string EffectName(Effect e) { return Info(e).name; }

std::string LocationName(Location l) {
  switch (l) {
    case Location::kInput:
      return "input";
    case Location::kOutput:
      return "output";
    case Location::kState:
      return "state";
  }
  return "input";
}

std::vector<std::string> EffectVocabulary() {
  std::vector<std::string> v;
  for (const auto& i : Infos()) v.push_back(i.name);
  return v;
}

Effect ParseEffect(const std::string& name) {
  for (const auto& i : Infos())
    if (name == i.name) return i.effect;
  std::string all;
  for (const auto& n : EffectVocabulary()) all += (all.empty() ? "" : ", ") + n;
  throw InputError(fmt::format("effect '{}' unknown; expected one of: {}", name, all));
}

Location ParseLocation(const std::string& name) {
  if (name == "input") return Location::kInput;
  if (name == "output") return Location::kOutput;
  if (name == "state") return Location::kState;
  throw InputError(fmt::format("location '{}' unknown; expected input, output or state", name));
}

std::vector<std::string> ParameterNames(Effect e) {
  std::vector<std::string> v;
  for (const char* p : Info(e).params) v.emplace_back(p);
  return v;
}

bool ParameterIsSmooth(Effect e, int index) {
  if (e == Effect::kDelay || e == Effect::kQuantization) return false;
  if (e == Effect::kHysteresis && index == 0) return false;
  return true;
}

std::vector<std::pair<Effect, Location>> CandidateEffects() {
  using E = Effect;
  using L = Location;
  return {{E::kBacklash, L::kInput},       {E::kDeadzone, L::kInput},        {E::kSaturation, L::kInput},
          {E::kRateLimit, L::kInput},      {E::kDelay, L::kInput},           {E::kQuantization, L::kInput},
          {E::kHysteresis, L::kInput},     {E::kDeadzone, L::kOutput},       {E::kSaturation, L::kOutput},
          {E::kQuantization, L::kOutput},  {E::kCoulombFriction, L::kState}, {E::kCubicStiffness, L::kState},
          {E::kStateSaturation, L::kState}};
}

std::vector<std::pair<Effect, Location>> ParseCandidates(const std::string& list) {
  std::vector<std::pair<Effect, Location>> out;
  std::size_t pos = 0;
  while (pos <= list.size()) {
    const auto comma = std::min(list.find(',', pos), list.size());
    const std::string tok = list.substr(pos, comma - pos);
    const auto at = tok.find('@');
    if (at == std::string::npos)
      throw InputError(fmt::format("effects: '{}' must be EFFECT@LOCATION, e.g. backlash@input", tok));
    const std::pair<Effect, Location> block{ParseEffect(tok.substr(0, at)), ParseLocation(tok.substr(at + 1))};
    const auto all = CandidateEffects();
    if (std::find(all.begin(), all.end(), block) == all.end())
      throw InputError(fmt::format("effects: '{}' is not a defined effect block (see docs/diagnose.md)", tok));
    out.push_back(block);
    pos = comma + 1;
  }
  return out;
}

bool EffectBlock::IsValid(std::string* error) const {
  auto fail = [&](std::string m) {
    if (error) *error = std::move(m);
    return false;
  };
  if (params.size() != ParameterNames(effect).size())
    return fail(fmt::format("effect {} needs {} parameters, got {}", EffectName(effect), ParameterNames(effect).size(),
                            params.size()));
  for (double p : params)
    if (!std::isfinite(p) && effect != Effect::kSaturation && effect != Effect::kStateSaturation)
      return fail(fmt::format("effect {}: parameters must be finite", EffectName(effect)));
  bool allowed = effect == Effect::kNone;
  for (const auto& [e, l] : CandidateEffects()) allowed = allowed || (e == effect && l == location);
  if (!allowed) return fail(fmt::format("effect {} is not defined at location {}", EffectName(effect), LocationName(location)));
  switch (effect) {
    case Effect::kBacklash:
    case Effect::kDeadzone:
      if (params[0] < 0) return fail(EffectName(effect) + ": half_width must be >= 0");
      break;
    case Effect::kRateLimit:
      if (!(params[0] > 0)) return fail("rate_limit: max_step must be > 0");
      break;
    case Effect::kDelay:
      if (params[0] < 0 || params[0] != std::round(params[0])) return fail("delay: samples must be an integer >= 0");
      break;
    case Effect::kQuantization:
      if (!(params[0] > 0)) return fail("quantization: step must be > 0");
      break;
    case Effect::kSaturation:
    case Effect::kStateSaturation:
      if (!(params[0] < params[1])) return fail(EffectName(effect) + ": lower must be < upper");
      break;
    case Effect::kHysteresis:
      if (params[0] < 0) return fail("hysteresis: threshold must be >= 0");
      break;
    default:
      break;
  }
  return true;
}

nlohmann::json EffectBlock::to_json() const {
  nlohmann::json p = nlohmann::json::object();
  const auto names = ParameterNames(effect);
  for (std::size_t i = 0; i < names.size() && i < params.size(); ++i) {
    if (std::isfinite(params[i]))
      p[names[i]] = params[i];
    else
      p[names[i]] = params[i] > 0 ? "inf" : "-inf";  // one-sided saturation
  }
  return {{"effect", EffectName(effect)}, {"location", LocationName(location)}, {"parameters", p}};
}

double ApplyStaticBlock(const EffectBlock& block, double v) {
  switch (block.effect) {
    case Effect::kDeadzone:
      return Sign(v) * std::max(std::abs(v) - block.params[0], 0.0);
    case Effect::kSaturation:
      return std::clamp(v, block.params[0], block.params[1]);
    case Effect::kQuantization:
      return block.params[0] * std::round(v / block.params[0]);
    default:
      return v;
  }
}

std::vector<double> ApplyInputBlock(const EffectBlock& block, const std::vector<double>& u) {
  const std::size_t n = u.size();
  std::vector<double> x(n);
  if (n == 0) return x;
  switch (block.effect) {
    case Effect::kBacklash: {
      const double w = block.params[0];
      double prev = u[0];
      for (std::size_t t = 0; t < n; ++t) prev = x[t] = std::clamp(prev, u[t] - w, u[t] + w);
      break;
    }
    case Effect::kRateLimit: {
      const double r = block.params[0];
      double prev = u[0];
      for (std::size_t t = 0; t < n; ++t) prev = x[t] = prev + std::clamp(u[t] - prev, -r, r);
      break;
    }
    case Effect::kDelay: {
      const long k = std::lround(block.params[0]);
      for (std::size_t t = 0; t < n; ++t) x[t] = static_cast<long>(t) >= k ? u[t - k] : u[0];
      break;
    }
    case Effect::kHysteresis: {
      const double beta = block.params[0], h = block.params[1];
      double s = u[0] >= 0 ? 1.0 : -1.0;
      for (std::size_t t = 0; t < n; ++t) {
        if (u[t] > beta) s = 1.0;
        if (u[t] < -beta) s = -1.0;
        x[t] = u[t] + h * s;
      }
      break;
    }
    default:
      for (std::size_t t = 0; t < n; ++t) x[t] = ApplyStaticBlock(block, u[t]);
  }
  return x;
}

bool AugmentedModel::simulate(const std::vector<double>& u, std::vector<double>* y) const {
  const std::size_t n = u.size();
  std::vector<double> x = block.location == Location::kInput ? ApplyInputBlock(block, u) : u;
  for (auto& v : x) v = nominal.input(v);
  const auto& a = nominal.linear.a;
  const auto& b = nominal.linear.b;
  const long d = nominal.linear.delay;
  double xmax = 0.0, bsum = 0.0;
  for (double v : x) xmax = std::max(xmax, std::abs(v));
  for (double v : b) bsum += std::abs(v);
  const double limit = 1e6 * (1.0 + xmax * bsum);
  const bool state = block.location == Location::kState;
  std::vector<double> z(n, 0.0);
  bool ok = true;
  for (std::size_t t = 0; t < n; ++t) {
    double acc = 0.0;
    for (std::size_t i = 1; i <= a.size() && i <= t; ++i) acc -= a[i - 1] * z[t - i];
    for (std::size_t j = 0; j < b.size(); ++j) {
      const long k = static_cast<long>(t) - d - static_cast<long>(j);
      if (k >= 0) acc += b[j] * x[k];
    }
    if (state) {
      const double z1 = t >= 1 ? z[t - 1] : 0.0, z2 = t >= 2 ? z[t - 2] : 0.0;
      switch (block.effect) {
        case Effect::kCubicStiffness:
          acc -= block.params[0] * z1 * z1 * z1;
          break;
        case Effect::kCoulombFriction:
          acc -= block.params[0] * Sign(z1 - z2);
          break;
        case Effect::kStateSaturation:
          acc = std::clamp(acc, block.params[0], block.params[1]);
          break;
        default:
          break;
      }
    }
    if (!std::isfinite(acc) || std::abs(acc) > limit) {
      ok = false;
      for (std::size_t s = t; s < n; ++s) z[s] = limit;
      break;
    }
    z[t] = acc;
  }
  for (auto& v : z) {
    v = nominal.output(v);
    if (block.location == Location::kOutput) v = ApplyStaticBlock(block, v);
    v += output_offset;
  }
  *y = std::move(z);
  return ok;
}

std::vector<double> AugmentedModel::simulate(const std::vector<double>& u) const {
  std::vector<double> y;
  simulate(u, &y);
  return y;
}

nlohmann::json AugmentedModel::to_json() const {
  nlohmann::json j = nominal.to_json();
  j["type"] = "augmented_hammerstein_wiener";
  j["effect_block"] = block.to_json();
  j["output_offset"] = output_offset;
  return j;
}

AugmentedModel AugmentedModel::from_json(const nlohmann::json& j) {
  AugmentedModel m;
  nlohmann::json base = j;
  base["type"] = "hammerstein_wiener";
  m.nominal = HwModel::from_json(base, {"output_offset", "effect_block"});  // the keys an augmented model adds
  if (j.contains("output_offset") && j["output_offset"].is_number()) m.output_offset = j["output_offset"].get<double>();
  if (j.contains("effect_block")) {
    try {
      const auto& e = j.at("effect_block");
      m.block.effect = ParseEffect(e.at("effect").get<std::string>());
      m.block.location = ParseLocation(e.value("location", "input"));
      const auto names = ParameterNames(m.block.effect);
      for (const auto& n : names) {
        const auto& v = e.at("parameters").at(n);
        if (v.is_string())
          m.block.params.push_back(v.get<std::string>() == "-inf" ? -HUGE_VAL : HUGE_VAL);
        else
          m.block.params.push_back(v.get<double>());
      }
    } catch (const nlohmann::json::exception& ex) {
      throw InputError(fmt::format("augmented model JSON, effect_block: {}", ex.what()));
    }
    std::string err;
    if (!m.block.IsValid(&err)) throw InputError("augmented model JSON: " + err);
  }
  return m;
}

}  // namespace hw::diagnose
