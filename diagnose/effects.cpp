#include "diagnose/effects.hpp"

#include "core/json_input.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <set>

#include <fmt/format.h>

#include "core/input_error.hpp"

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
      {Effect::kDeadzone, "deadzone", {"half_width", "centre"}},
      {Effect::kSaturation, "saturation", {"lower", "upper"}},
      {Effect::kRateLimit, "rate_limit", {"max_step"}},
      {Effect::kDelay, "delay", {"samples"}},
      {Effect::kQuantization, "quantization", {"step", "offset"}},
      {Effect::kCoulombFriction, "coulomb_friction", {"level_up", "level_down"}},
      {Effect::kHysteresis, "hysteresis", {"threshold", "height"}},
      {Effect::kCubicStiffness, "cubic_stiffness", {"k3"}},
      {Effect::kStateSaturation, "state_saturation", {"lower", "upper"}},
      {Effect::kStiction, "stiction", {"static_band", "kinetic_band"}},
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

bool IsLimitPair(Effect e) { return e == Effect::kSaturation || e == Effect::kStateSaturation; }

// Every key of `j` must be in `allowed`; the message names the key, where it is and what is allowed.
void RequireKnownKeys(const nlohmann::json& j, const std::set<std::string>& allowed, const std::string& where) {
  if (!j.is_object()) throw InputError(fmt::format("{}: expected a JSON object", where));
  for (auto it = j.begin(); it != j.end(); ++it)
    if (!allowed.count(it.key())) {
      std::string list;
      for (const auto& a : allowed) list += (list.empty() ? "" : ", ") + a;
      throw InputError(fmt::format("{}: unknown key '{}'; expected only: {}", where, it.key(), list));
    }
}

void CheckStaticMapKeys(const nlohmann::json& j, const std::string& where) {
  RequireKnownKeys(j, {"kind", "coefficients", "x", "y"}, where);
}

// Coulomb friction on the velocity update: pulled towards 0 by the level of its direction, stuck at 0
// when it would cross.
double FrictionStep(double v, double up, double down) {
  if (v > 0) return std::max(v - up, 0.0);
  if (v < 0) return std::min(v + down, 0.0);
  return 0.0;
}

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

std::string StateVariableName(StateVariable s) { return s == StateVariable::kVelocity ? "velocity" : "position"; }

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

StateVariable ParseStateVariable(const std::string& name) {
  if (name == "position") return StateVariable::kPosition;
  if (name == "velocity") return StateVariable::kVelocity;
  throw InputError(fmt::format("state variable '{}' unknown; expected position or velocity", name));
}

std::vector<std::string> ParameterNames(Effect e) {
  std::vector<std::string> v;
  for (const char* p : Info(e).params) v.emplace_back(p);
  return v;
}

bool ParameterIsSmooth(Effect e, int index) {
  if (e == Effect::kDelay || e == Effect::kQuantization) return false;
  if (e == Effect::kHysteresis && index == 0) return false;
  // Stiction's bands decide when the stem sticks and slips: the cost jumps with them, and LM from a grid
  // point settles on a backlash-like band (kinetic = static) instead of the stick-slip jump.
  if (e == Effect::kStiction) return false;
  return true;
}

std::vector<std::pair<Effect, Location>> CandidateEffects() {
  using E = Effect;
  using L = Location;
  return {{E::kBacklash, L::kInput},       {E::kDeadzone, L::kInput},        {E::kSaturation, L::kInput},
          {E::kRateLimit, L::kInput},      {E::kDelay, L::kInput},           {E::kQuantization, L::kInput},
          {E::kHysteresis, L::kInput},     {E::kStiction, L::kInput},        {E::kDeadzone, L::kOutput},
          {E::kSaturation, L::kOutput},    {E::kQuantization, L::kOutput},   {E::kCoulombFriction, L::kState},
          {E::kCubicStiffness, L::kState}, {E::kStateSaturation, L::kState}};
}

bool IsDefined(Effect e, Location l) {
  for (const auto& [ce, cl] : CandidateEffects())
    if (ce == e && cl == l) return true;
  return false;
}

void ClampToPhysicalRange(EffectBlock* b) {
  auto& p = b->params;
  switch (b->effect) {
    case Effect::kBacklash:
    case Effect::kDeadzone:
      p[0] = std::abs(p[0]);
      break;
    case Effect::kRateLimit:
      p[0] = std::max(std::abs(p[0]), 1e-12);
      break;
    case Effect::kQuantization:
      p[0] = std::max(std::abs(p[0]), 1e-12);
      break;
    case Effect::kDelay:
      p[0] = std::max(1.0, std::round(p[0]));
      break;
    case Effect::kSaturation:
    case Effect::kStateSaturation:
      if (p[0] > p[1]) std::swap(p[0], p[1]);
      break;
    case Effect::kHysteresis:
      p[0] = std::abs(p[0]);
      p[1] = std::max(p[1], 0.0);  // a negative relay height is not hysteresis: the block switches off
      break;
    case Effect::kCoulombFriction:
      p[0] = std::max(p[0], 0.0);  // friction never pushes: a level below 0 is held at 0
      p[1] = std::max(p[1], 0.0);
      break;
    case Effect::kStiction:
      p[0] = std::abs(p[0]);
      p[1] = std::min(std::abs(p[1]), p[0]);
      break;
    default:
      break;
  }
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
    const Effect e = ParseEffect(tok.substr(0, at));
    const Location l = ParseLocation(tok.substr(at + 1));
    if (!IsDefined(e, l))
      throw InputError(fmt::format("effects: '{}' is not a defined effect block (see docs/diagnose.md)", tok));
    out.emplace_back(e, l);
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
    if (!std::isfinite(p) && !IsLimitPair(effect))
      return fail(fmt::format("effect {}: parameters must be finite", EffectName(effect)));
  if (effect != Effect::kNone && !IsDefined(effect, location))
    return fail(fmt::format("effect {} is not defined at location {}", EffectName(effect), LocationName(location)));
  const std::string n = EffectName(effect);
  switch (effect) {
    case Effect::kBacklash:
      if (params[0] < 0) return fail(n + ": half_width must be >= 0");
      break;
    case Effect::kDeadzone:
      if (params[0] < 0 || !std::isfinite(params[1])) return fail(n + ": half_width must be >= 0 and centre finite");
      break;
    case Effect::kRateLimit:
      if (!(params[0] > 0)) return fail("rate_limit: max_step must be > 0");
      break;
    case Effect::kDelay:
      if (params[0] < 1 || params[0] != std::round(params[0])) return fail("delay: samples must be an integer >= 1");
      break;
    case Effect::kQuantization:
      if (!(params[0] > 0) || !std::isfinite(params[1])) return fail("quantization: step must be > 0 and offset finite");
      break;
    case Effect::kSaturation:
    case Effect::kStateSaturation:
      if (!(params[0] < params[1])) return fail(n + ": lower must be < upper");
      break;
    case Effect::kHysteresis:
      if (params[0] < 0 || params[1] < 0) return fail("hysteresis: threshold and height must be >= 0");
      break;
    case Effect::kCoulombFriction:
      if (params[0] < 0 || params[1] < 0) return fail("coulomb_friction: level_up and level_down must be >= 0");
      break;
    case Effect::kStiction:
      if (!(params[1] >= 0 && params[0] >= params[1]))
        return fail("stiction: needs static_band >= kinetic_band >= 0");
      break;
    default:
      break;
  }
  return true;
}

std::string EffectBlock::Label() const { return EffectName(effect) + "@" + LocationName(location); }

nlohmann::json EffectBlock::to_json() const {
  nlohmann::json p = nlohmann::json::object();
  const auto names = ParameterNames(effect);
  for (std::size_t i = 0; i < names.size() && i < params.size(); ++i) {
    if (std::isfinite(params[i]))
      p[names[i]] = params[i];
    else
      p[names[i]] = params[i] > 0 ? "inf" : "-inf";  // one-sided saturation
  }
  nlohmann::json j = {{"effect", EffectName(effect)}, {"location", LocationName(location)}, {"parameters", p}};
  if (location == Location::kState) j["state_variable"] = StateVariableName(state_variable);
  return j;
}

EffectBlock EffectBlock::from_json(const nlohmann::json& e) {
  RequireKnownKeys(e, {"effect", "location", "parameters", "state_variable"}, "effect block");
  EffectBlock b;
  try {
    b.effect = ParseEffect(e.at("effect").get<std::string>());
    b.location = ParseLocation(e.value("location", "input"));
    if (e.contains("state_variable")) b.state_variable = ParseStateVariable(e.at("state_variable").get<std::string>());
    const auto names = ParameterNames(b.effect);
    const auto& ps = e.at("parameters");
    RequireKnownKeys(ps, std::set<std::string>(names.begin(), names.end()),
                     fmt::format("effect block {} parameters", EffectName(b.effect)));
    for (const auto& n : names) {
      if (((b.effect == Effect::kQuantization && std::string(n) == "offset") ||
           (b.effect == Effect::kDeadzone && std::string(n) == "centre")) &&
          !ps.contains(n)) {
        b.params.push_back(0.0);  // models written before the grid offset and the band's centre existed
        continue;
      }
      const auto& v = ps.at(n);
      if (v.is_string()) {
        const auto s = v.get<std::string>();
        if (s != "inf" && s != "-inf")
          throw InputError(fmt::format("effect block parameter {}: '{}' is not a number, \"inf\" or \"-inf\"", n, s));
        b.params.push_back(s == "-inf" ? -HUGE_VAL : HUGE_VAL);
      } else {
        b.params.push_back(v.get<double>());
      }
    }
  } catch (const nlohmann::json::exception& ex) {
    throw InputError(fmt::format("effect block: {}", ex.what()));
  }
  std::string err;
  if (!b.IsValid(&err)) throw InputError("effect block: " + err);
  return b;
}

// Rounding smoothed over a width w (in steps): the staircase k + sum of logistic steps at the nearest
// half-integers, which tends to round(x) as w -> 0.
double SmoothRound(double x, double w) {
  const double k = std::floor(x), f = x - k;
  auto step = [w](double d) { return 1.0 / (1.0 + std::exp(-d / w)); };
  return k + step(f - 0.5) + step(f - 1.5) - step(-f - 0.5);
}

double ApplyStaticBlock(const EffectBlock& block, double v, double smoothing) {
  switch (block.effect) {
    case Effect::kDeadzone: {
      // A dead band of half-width d around c (0 unless the band sits at an operating point).
      const double c = block.params.size() > 1 ? block.params[1] : 0.0;
      return c + Sign(v - c) * std::max(std::abs(v - c) - block.params[0], 0.0);
    }
    case Effect::kSaturation:
      return std::clamp(v, block.params[0], block.params[1]);
    case Effect::kQuantization: {
      // Levels offset + k step: the grid of a quantizer need not pass through the recording's 0.
      const double o = block.params.size() > 1 ? block.params[1] : 0.0;
      const double x = (v - o) / block.params[0];
      return o + block.params[0] * (smoothing > 0 ? SmoothRound(x, smoothing) : std::round(x));
    }
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
    case Effect::kStiction: {
      // He, Wang, Pottmann, Qin (2007): stuck until the input has moved more than the static band from
      // the stem; then the stem follows at the kinetic lag until the input reverses or stops.
      // A moving stem sits exactly fd behind the input, so when the input holds still |u_t - x_{t-1}|
      // equals fd up to the rounding of u - (u - fd), which falls on either side of fd (about 4 holds
      // in 10). A difference must therefore exceed a band by kStictionBandTolerance relative to the
      // signal's magnitude to count: a hold always stops the stem, whatever the last bits.
      const double fs = block.params[0], fd = block.params[1];
      double prev = u[0], dir = 0.0;
      bool stuck = true;
      for (std::size_t t = 0; t < n; ++t) {
        const double d = u[t] - prev;
        const double tol = kStictionBandTolerance * (std::abs(u[t]) + std::abs(prev) + fs);
        if (stuck && std::abs(d) > fs + tol) {
          stuck = false;
          dir = Sign(d);
        } else if (!stuck && !(Sign(d) == dir && std::abs(d) > fd + tol)) {
          stuck = true;
        }
        prev = x[t] = stuck ? prev : u[t] - dir * fd;
      }
      break;
    }
    default:
      for (std::size_t t = 0; t < n; ++t) x[t] = ApplyStaticBlock(block, u[t]);
  }
  return x;
}

std::vector<double> ParametersInRecordingUnits(const EffectBlock& b, const AugmentedModel& m) {
  std::vector<double> p = b.params;
  if (b.effect == Effect::kStateSaturation && b.location == Location::kState)
    for (auto& v : p)
      if (std::isfinite(v)) v = m.nominal.output(v) + m.output_offset;
  return p;
}

std::vector<double> FrictionLevelsInInputUnits(const EffectBlock& b, const AugmentedModel& m) {
  if (b.effect != Effect::kCoulombFriction || m.nominal.input.kind != StaticMap::Kind::kIdentity) return {};
  double gain = 0.0;
  for (double v : m.nominal.linear.b) gain += v;
  if (!(std::abs(gain) > 0)) return {};
  return {b.params[0] / std::abs(gain), b.params[1] / std::abs(gain)};
}

std::string ParameterText(const EffectBlock& b, const AugmentedModel& m) {
  const auto names = ParameterNames(b.effect);
  const auto p = ParametersInRecordingUnits(b, m);
  const auto force = FrictionLevelsInInputUnits(b, m);
  std::string s;
  for (std::size_t i = 0; i < names.size() && i < p.size(); ++i) {
    s += fmt::format("{}{} = {:.4g}", s.empty() ? "" : ", ", names[i], p[i]);
    if (i < force.size()) s += fmt::format(" ({:.4g} in input units)", force[i]);
  }
  return s;
}

std::string AugmentedModel::Label() const {
  if (blocks.empty()) return "none";
  std::string s;
  for (const auto& b : blocks) s += (s.empty() ? "" : "+") + b.Label();
  return s;
}

AugmentedModel AugmentedModel::WithoutBlocks() const {
  AugmentedModel m = *this;
  m.blocks.clear();
  return m;
}

std::vector<double> AugmentedModel::AfterInputBlocks(const std::vector<double>& u) const {
  std::vector<double> x = u;
  for (const auto& b : blocks) {
    if (b.location != Location::kInput) continue;
    if (b.effect == Effect::kQuantization && input_quantizer_smoothing > 0) {
      for (auto& v : x) v = ApplyStaticBlock(b, v, input_quantizer_smoothing);
    } else {
      x = ApplyInputBlock(b, x);
    }
  }
  return x;
}

bool AugmentedModel::simulate(const std::vector<double>& u, std::vector<double>* y) const {
  const std::size_t n = u.size();
  std::vector<double> x = AfterInputBlocks(u);
  for (auto& v : x) v = nominal.input(v);
  const auto& a = nominal.linear.a;
  const auto& bb = nominal.linear.b;
  const long d = nominal.linear.delay;
  const EffectBlock *friction = nullptr, *cubic = nullptr, *clamp = nullptr;
  for (const auto& b : blocks) {
    if (b.location != Location::kState) continue;
    if (b.effect == Effect::kCoulombFriction) friction = &b;
    if (b.effect == Effect::kCubicStiffness) cubic = &b;
    if (b.effect == Effect::kStateSaturation) clamp = &b;
  }
  double xmax = 0.0, bsum = 0.0, zmax = 0.0;
  for (double v : x) xmax = std::max(xmax, std::abs(v));
  for (double v : bb) bsum += std::abs(v);
  for (double v : initial_state) zmax = std::max(zmax, std::abs(v));
  const double limit = 1e6 * (1.0 + xmax * bsum + zmax);
  // z before the first sample comes from the initial state (zero when empty).
  const std::size_t pad = std::max<std::size_t>(a.size(), 2);
  std::vector<double> zz(pad + n, 0.0);
  for (std::size_t i = 0; i < initial_state.size() && i < pad; ++i) zz[pad - 1 - i] = initial_state[i];
  bool ok = true;
  for (std::size_t t = 0; t < n; ++t) {
    const std::size_t k0 = pad + t;
    double acc = 0.0;
    for (std::size_t i = 1; i <= a.size(); ++i) acc -= a[i - 1] * zz[k0 - i];
    for (std::size_t j = 0; j < bb.size(); ++j) {
      const long k = static_cast<long>(t) - d - static_cast<long>(j);
      if (k >= 0) acc += bb[j] * x[k];
    }
    const double z1 = zz[k0 - 1];
    if (cubic) acc -= cubic->params[0] * z1 * z1 * z1;
    if (friction) {
      const bool velocity = friction->state_variable == StateVariable::kVelocity;
      const double v = FrictionStep(velocity ? acc : acc - z1, friction->params[0], friction->params[1]);
      acc = velocity ? v : z1 + v;
    }
    if (clamp) acc = std::clamp(acc, clamp->params[0], clamp->params[1]);
    if (!std::isfinite(acc) || std::abs(acc) > limit) {
      ok = false;
      for (std::size_t s = k0; s < zz.size(); ++s) zz[s] = limit;
      break;
    }
    zz[k0] = acc;
  }
  y->assign(zz.begin() + pad, zz.end());
  for (auto& v : *y) {
    v = nominal.output(v) + output_offset;
    for (const auto& b : blocks)
      if (b.location == Location::kOutput) v = ApplyStaticBlock(b, v, output_quantizer_smoothing);
  }
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
  nlohmann::json bl = nlohmann::json::array();
  for (const auto& b : blocks) bl.push_back(b.to_json());
  j["effect_blocks"] = bl;
  j["output_offset"] = output_offset;
  j["initial_state"] = initial_state;
  return j;
}

AugmentedModel AugmentedModel::from_json(const nlohmann::json& j) {
  RequireKnownKeys(j,
                   {"type", "name", "input_nonlinearity", "linear", "output_nonlinearity", "effect_blocks",
                    "effect_block", "output_offset", "initial_state"},
                   "model JSON");
  if (j.contains("linear")) RequireKnownKeys(j.at("linear"), {"a", "b", "delay"}, "model JSON, linear");
  for (const char* k : {"input_nonlinearity", "output_nonlinearity"})
    if (j.contains(k)) CheckStaticMapKeys(j.at(k), fmt::format("model JSON, {}", k));
  // Any JSON value may stand there: compared as JSON, not read as a string first.
  const nlohmann::json type = j.value("type", nlohmann::json("hammerstein_wiener"));
  if (type != "hammerstein_wiener" && type != "augmented_hammerstein_wiener")
    throw InputError(fmt::format("model JSON: type {} unknown; expected \"hammerstein_wiener\" or "
                                 "\"augmented_hammerstein_wiener\"", type.dump()));
  AugmentedModel m;
  nlohmann::json base = j;  // the plain part goes to the project's reader
  for (const char* k : {"effect_blocks", "effect_block", "output_offset", "initial_state"}) base.erase(k);
  base["type"] = "hammerstein_wiener";
  m.nominal = HwModel::from_json(base);
  try {
    if (j.contains("output_offset")) m.output_offset = j.at("output_offset").get<double>();
    if (j.contains("initial_state")) m.initial_state = j.at("initial_state").get<std::vector<double>>();
  } catch (const nlohmann::json::exception& ex) {
    throw InputError(fmt::format("model JSON, output_offset / initial_state: {}", ex.what()));
  }
  if (m.initial_state.size() > m.nominal.linear.a.size())
    throw InputError(fmt::format("model JSON: initial_state has {} values but the linear block has {} a coefficients",
                                 m.initial_state.size(), m.nominal.linear.a.size()));
  if (j.contains("effect_block")) m.blocks.push_back(EffectBlock::from_json(j.at("effect_block")));
  if (j.contains("effect_blocks")) {
    if (!j.at("effect_blocks").is_array()) throw InputError("model JSON: effect_blocks must be an array");
    for (const auto& b : j.at("effect_blocks")) m.blocks.push_back(EffectBlock::from_json(b));
  }
  m.blocks.erase(std::remove_if(m.blocks.begin(), m.blocks.end(),
                                [](const EffectBlock& b) { return b.effect == Effect::kNone; }),
                 m.blocks.end());
  if (m.blocks.size() > 2) throw InputError("model JSON: at most two effect blocks");
  return m;
}

AugmentedModel AugmentedModel::Load(const std::string& path) {
  const nlohmann::json j = ReadJsonFile(path, "model JSON file");  // names the file: missing, a directory, bad JSON
  try {
    return from_json(j);
  } catch (const InputError& e) {
    throw InputError(fmt::format("{}: {}", path, e.what()));
  }
}

}  // namespace hw::diagnose
