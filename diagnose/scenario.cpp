#include "diagnose/scenario.hpp"

#include <algorithm>
#include <cmath>
#include <random>

#include <fmt/format.h>

#include "core/input_error.hpp"
#include "diagnose/signal_stats.hpp"

namespace hw::diagnose {
namespace {

using Vec = std::vector<double>;

// Low-passed random steps with a small dither: levels, rates and reversals all get exercised.
Vec MakeInput(std::mt19937_64& rng, std::size_t n) {
  std::uniform_int_distribution<int> hold(8, 40);
  std::uniform_real_distribution<double> level(-1.0, 1.0);
  std::normal_distribution<double> g(0.0, 1.0);
  Vec u(n);
  double s = level(rng), x = 0.0;
  int left = hold(rng);
  for (std::size_t t = 0; t < n; ++t) {
    if (left-- <= 0) s = level(rng), left = hold(rng);
    x = 0.6 * x + 0.4 * s;
    u[t] = x + 0.02 * g(rng);
  }
  return u;
}

Vec Contribution(const AugmentedModel& m, const HwModel& lin, const Vec& u, bool* ok) {
  Vec w;
  *ok = m.simulate(u, &w);
  const Vec wl = lin.simulate(u);
  for (std::size_t t = 0; t < w.size(); ++t) w[t] -= wl[t];
  return w;
}

}  // namespace

Location DefaultLocation(Effect e) {
  switch (e) {
    case Effect::kCoulombFriction:
    case Effect::kCubicStiffness:
    case Effect::kStateSaturation:
      return Location::kState;
    default:
      return Location::kInput;
  }
}

bool ScenarioOptions::IsValid(std::string* error) const {
  auto fail = [&](std::string m) {
    if (error) *error = std::move(m);
    return false;
  };
  if (!(effect_rms_ratio > 0)) return fail("effect_rms_ratio must be > 0");
  if (!(effect_fraction >= 0 && effect_fraction < 1)) return fail("effect_fraction must be in [0, 1)");
  if (samples < 200) return fail("samples must be >= 200");
  if (location < -1 || location > 2) return fail("location must be input, output or state");
  if (effect != Effect::kNone) {
    const Location l = location < 0 ? DefaultLocation(effect) : static_cast<Location>(location);
    EffectBlock b{effect, l, Vec(ParameterNames(effect).size(), 1.0)};
    if (effect == Effect::kSaturation || effect == Effect::kStateSaturation) b.params = {0.0, 1.0};
    std::string e;
    if (!b.IsValid(&e)) return fail(e);
  }
  return true;
}

nlohmann::json Scenario::truth_json() const {
  nlohmann::json blocks = nlohmann::json::array();
  for (const auto& b : truth.blocks) blocks.push_back(b.to_json());
  return {{"effect", EffectName(truth.effect())},
          {"location", truth.has_block() ? LocationName(truth.blocks.front().location) : "none"},
          {"blocks", blocks},
          {"noise_std", noise_std},
          {"effect_rms", effect_rms},
          {"model", truth.to_json()}};
}

Scenario MakeScenario(const ScenarioOptions& o) {
  std::string err;
  if (!o.IsValid(&err)) throw InputError("scenario: " + err);
  std::mt19937_64 rng(0x9e3779b97f4a7c15ULL ^ (static_cast<unsigned long long>(o.seed) * 7919ULL +
                                                static_cast<unsigned long long>(o.effect) * 104729ULL));
  std::uniform_real_distribution<double> U(0.0, 1.0);
  Scenario sc;
  // Lightly damped second-order system, DC gain 1.
  const double r = 0.85 + 0.1 * U(rng), th = 0.15 + 0.3 * U(rng);
  const double a1 = -2 * r * std::cos(th), a2 = r * r;
  const double b0 = 0.2 + 0.6 * U(rng);
  const double gain = 1 + a1 + a2;
  HwModel lin;
  lin.linear = {{a1, a2}, {b0 * gain, (1 - b0) * gain}, 0};
  lin.name = "scenario linear part";
  sc.linear_truth = lin;
  const Vec u_id = MakeInput(rng, o.samples), u_va = MakeInput(rng, o.samples);
  const Vec w_lin = lin.simulate(u_id);
  const double frac = o.effect_fraction > 0 ? o.effect_fraction : 0.04 + 0.04 * U(rng);
  const double target = frac * StdDev(w_lin);

  AugmentedModel truth{lin, {}, 0.0, {}};
  if (o.effect != Effect::kNone) {
    const Location loc = o.location < 0 ? DefaultLocation(o.effect) : static_cast<Location>(o.location);
    const Vec& lv = loc == Location::kInput ? u_id : w_lin;
    Vec du;
    for (std::size_t t = 1; t < u_id.size(); ++t) du.push_back(std::abs(u_id[t] - u_id[t - 1]));
    double vmax = 0.0;
    for (double v : lv) vmax = std::max(vmax, std::abs(v));
    const double range = Quantile(lv, 1.0) - Quantile(lv, 0.0);
    const bool upper = U(rng) < 0.5;
    const double beta = (0.2 + 0.4 * U(rng)) * vmax;
    // Force scale of the numerator, for friction and stiffness.
    const double force = Rms(LinearBlock{{}, lin.linear.b, 0}.simulate(u_id));
    const double zr = Rms(w_lin);
    const int k_delay = 1 + static_cast<int>(o.seed % 3);
    const double asymmetry = 0.6 + 0.4 * U(rng);    // friction level down / level up
    const double stick_ratio = 0.3 + 0.4 * U(rng);  // kinetic / static band of a sticky valve
    auto block_for = [&](double s) -> EffectBlock {
      switch (o.effect) {
        case Effect::kBacklash:
          return {o.effect, loc, {s * 0.3 * range}};
        case Effect::kDeadzone:
          return {o.effect, loc, {s * 0.6 * vmax, 0.0}};
        case Effect::kSaturation:
        case Effect::kStateSaturation: {
          const double q = std::max(1e-4, 0.35 * s);
          return upper ? EffectBlock{o.effect, loc, {-HUGE_VAL, Quantile(lv, 1 - q)}}
                       : EffectBlock{o.effect, loc, {Quantile(lv, q), HUGE_VAL}};
        }
        case Effect::kRateLimit:
          return {o.effect, loc, {std::max(1e-6, (1 - s)) * Quantile(du, 1.0)}};
        case Effect::kDelay:
          return {o.effect, loc, {double(k_delay)}};
        case Effect::kQuantization:
          return {o.effect, loc, {std::max(1e-6, s * 0.5 * range), 0.0}};
        case Effect::kHysteresis:
          return {o.effect, loc, {beta, s * 0.5 * StdDev(u_id)}};
        case Effect::kStiction:
          return {o.effect, loc, {s * 0.3 * range, s * 0.3 * range * stick_ratio}};
        case Effect::kCoulombFriction:
          return {o.effect, loc, {s * 0.5 * force, s * 0.5 * force * asymmetry}};
        case Effect::kCubicStiffness:
          return {o.effect, loc, {s * 0.5 * force / (zr * zr * zr)}};
        default:
          return {};
      }
    };
    auto contrib_rms = [&](double s) {
      AugmentedModel m{lin, {block_for(s)}, 0.0, {}};
      bool ok = true;
      const Vec c = Contribution(m, lin, u_id, &ok);
      return ok ? Rms(c) : HUGE_VAL;
    };
    double lo = 0.0, hi = 1.0, s = 1.0;
    if (o.effect != Effect::kDelay && contrib_rms(1.0) > target) {
      for (int it = 0; it < 50; ++it) {
        const double mid = 0.5 * (lo + hi);
        (contrib_rms(mid) < target ? lo : hi) = mid;
      }
      s = 0.5 * (lo + hi);
    }
    truth.blocks = {block_for(s)};
  }
  sc.truth = truth;
  bool ok = true;
  sc.ident_contribution = Contribution(truth, lin, u_id, &ok);
  if (!ok) throw InputError("scenario: the true system diverged; try another seed");
  sc.effect_rms = o.effect == Effect::kNone ? target : Rms(sc.ident_contribution);
  sc.noise_std = sc.effect_rms / o.effect_rms_ratio;
  std::normal_distribution<double> g(0.0, sc.noise_std);
  auto record = [&](const Vec& u, const std::string& name) {
    Recording rec;
    rec.name = name;
    rec.u = u;
    rec.y = truth.simulate(u);
    for (auto& v : rec.y) v += g(rng);
    rec.t.resize(u.size());
    for (std::size_t t = 0; t < u.size(); ++t) rec.t[t] = static_cast<double>(t);
    return rec;
  };
  sc.ident = record(u_id, "scenario identification");
  sc.valid = record(u_va, "scenario validation");
  sc.ident_active.resize(o.samples);
  for (std::size_t t = 0; t < o.samples; ++t) sc.ident_active[t] = std::abs(sc.ident_contribution[t]) > sc.noise_std;
  return sc;
}

}  // namespace hw::diagnose
