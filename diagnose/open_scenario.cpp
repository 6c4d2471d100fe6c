#include "diagnose/open_scenario.hpp"

#include <algorithm>
#include <cmath>
#include <complex>
#include <random>

#include <fmt/format.h>

#include "core/csv_table.hpp"
#include "diagnose/refit.hpp"
#include "diagnose/signal_stats.hpp"

namespace hw::diagnose {
namespace {

using Vec = std::vector<double>;
using Rng = std::mt19937_64;

double Uniform(Rng& rng, double lo, double hi) { return std::uniform_real_distribution<double>(lo, hi)(rng); }
int UniformInt(Rng& rng, int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(rng); }


LinearBlock RandomLinear(Rng& rng) {
  const int na = UniformInt(rng, 1, 3);
  std::vector<std::complex<double>> poles;
  if (na >= 2 && Uniform(rng, 0, 1) < 0.6) {
    const double r = Uniform(rng, 0.6, 0.97), th = Uniform(rng, 0.05, 1.2);
    poles = {std::polar(r, th), std::polar(r, -th)};
  }
  while (static_cast<int>(poles.size()) < na) poles.emplace_back(Uniform(rng, 0.3, 0.97), 0.0);
  LinearBlock lb;
  lb.a = DenominatorFromRoots(poles);
  const int nb = UniformInt(rng, 1, 3);
  lb.b.resize(nb);
  lb.b[0] = 1.0;
  for (int j = 1; j < nb; ++j) lb.b[j] = Uniform(rng, -0.4, 0.8);  // zeros of mild influence
  lb.delay = UniformInt(rng, 0, 2);
  double num = 0.0, den = 1.0;
  for (double v : lb.b) num += v;
  for (double v : lb.a) den += v;
  const double scale = Uniform(rng, 0.5, 2.0) * den / num;
  for (auto& v : lb.b) v *= scale;
  return lb;
}

Vec Multisine(Rng& rng, std::size_t n) {
  const int k = UniformInt(rng, 5, 30);
  const double fmax = Uniform(rng, 0.03, 0.2);  // cycles per sample
  Vec u(n, 0.0);
  for (int i = 0; i < k; ++i) {
    const double f = fmax * (i + 1) / k, ph = Uniform(rng, 0, 2 * M_PI);
    for (std::size_t t = 0; t < n; ++t) u[t] += std::sin(2 * M_PI * f * t + ph);
  }
  return u;
}

Vec Prbs(Rng& rng, std::size_t n) {
  const int clock = UniformInt(rng, 2, 15);
  Vec u(n);
  double level = 1.0;
  for (std::size_t t = 0; t < n; ++t) {
    if (t % clock == 0 && Uniform(rng, 0, 1) < 0.5) level = -level;
    u[t] = level;
  }
  return u;
}

Vec Steps(Rng& rng, std::size_t n) {
  const int lo = UniformInt(rng, 5, 30), hi = lo + UniformInt(rng, 10, 80);
  Vec u(n);
  double level = Uniform(rng, -1, 1);
  int left = UniformInt(rng, lo, hi);
  for (std::size_t t = 0; t < n; ++t) {
    if (left-- <= 0) level = Uniform(rng, -1, 1), left = UniformInt(rng, lo, hi);
    u[t] = level;
  }
  return u;
}

Vec FilteredNoise(Rng& rng, std::size_t n) {
  const double p = Uniform(rng, 0.5, 0.95);
  const bool second = Uniform(rng, 0, 1) < 0.5;
  std::normal_distribution<double> g(0.0, 1.0);
  Vec u(n);
  double x1 = 0.0, x2 = 0.0;
  for (std::size_t t = 0; t < n; ++t) {
    x1 = p * x1 + (1 - p) * g(rng);
    x2 = second ? p * x2 + (1 - p) * x1 : x1;
    u[t] = x2;
  }
  return u;
}

// Standardised to zero mean and unit standard deviation.
Vec Standardise(Vec u) {
  double m = 0.0;
  for (double v : u) m += v;
  m /= u.size();
  const double s = std::max(StdDev(u), 1e-12);
  for (auto& v : u) v = (v - m) / s;
  return u;
}

// Closed loop: u_t = r_t + k (r_t - y_{t-1}) on the measured output (noise included), so the input is
// correlated with past noise. Simulated sample by sample on prefixes.
Vec CloseLoop(const AugmentedModel& plant, const Vec& r, double k, double noise, Rng& rng, Vec* y_meas) {
  const std::size_t n = r.size();
  std::normal_distribution<double> g(0.0, noise);
  Vec u, y(n, 0.0);
  u.reserve(n);
  double last = 0.0;
  for (std::size_t t = 0; t < n; ++t) {
    u.push_back(r[t] + k * (r[t] - last));
    Vec w;
    plant.simulate(u, &w);  // prefix simulation: O(n^2) in all, fine for n <= 1400
    y[t] = w.back() + g(rng);
    last = y[t];
  }
  if (y_meas) *y_meas = y;
  return u;
}

InputKind DrawInputKind(Rng& rng) { return static_cast<InputKind>(UniformInt(rng, 0, 4)); }

Vec OpenLoopInput(InputKind kind, Rng& rng, std::size_t n) {
  switch (kind) {
    case InputKind::kMultisine:
      return Standardise(Multisine(rng, n));
    case InputKind::kPrbs:
      return Standardise(Prbs(rng, n));
    case InputKind::kFilteredNoise:
      return Standardise(FilteredNoise(rng, n));
    default:
      return Standardise(Steps(rng, n));
  }
}

// Block of the effect with strength s in (0, 1]; shape factors drawn once per scenario.
struct EffectShape {
  Effect effect;
  Location location;
  bool upper = true, two_sided = false;
  double asymmetry = 0.8, stick_ratio = 0.5, beta = 0.3;
  int delay = 1;
  EffectBlock Block(double s, const Vec& lv, const Vec& du, double force, double zr) const {
    const double range = Quantile(lv, 1.0) - Quantile(lv, 0.0);
    const double mid = 0.5 * (Quantile(lv, 1.0) + Quantile(lv, 0.0));
    double vmax = 0.0;
    for (double v : lv) vmax = std::max(vmax, std::abs(v - mid));
    switch (effect) {
      case Effect::kBacklash:
        return {effect, location, {s * 0.3 * range}};
      case Effect::kDeadzone:
        return {effect, location, {s * 0.6 * vmax, 0.0}};
      case Effect::kSaturation:
      case Effect::kStateSaturation: {
        const double q = std::max(1e-4, 0.4 * s);
        const double hi = Quantile(lv, 1 - q), lo = Quantile(lv, q);
        if (two_sided) return {effect, location, {lo, hi}};
        return upper ? EffectBlock{effect, location, {-HUGE_VAL, hi}} : EffectBlock{effect, location, {lo, HUGE_VAL}};
      }
      case Effect::kRateLimit:
        return {effect, location, {std::max(1e-6, 1 - s) * Quantile(du, 1.0)}};
      case Effect::kDelay:
        return {effect, location, {double(delay)}};
      case Effect::kQuantization:
        return {effect, location, {std::max(1e-6, s * 0.5 * range), 0.0}};
      case Effect::kHysteresis:
        return {effect, location, {beta * vmax, s * 0.5 * StdDev(lv)}};
      case Effect::kStiction:
        return {effect, location, {s * 0.3 * range, s * 0.3 * range * stick_ratio}};
      case Effect::kCoulombFriction:
        return {effect, location, {s * 0.5 * force, s * 0.5 * force * asymmetry}};
      case Effect::kCubicStiffness:
        return {effect, location, {s * 0.5 * force / (zr * zr * zr)}};
      default:
        return {};
    }
  }
};

double ContributionRms(const AugmentedModel& m, const HwModel& lin, const Vec& u, Vec* contrib) {
  Vec w;
  if (!m.simulate(u, &w)) return HUGE_VAL;
  const Vec wl = AugmentedModel{lin, {}, 0.0, {}}.simulate(u);
  for (std::size_t t = 0; t < w.size(); ++t) w[t] -= wl[t];
  if (contrib) *contrib = w;
  return Rms(w);
}

// A size the bisection below ends under (of 1, its start) is a search that found no size at all.
constexpr double kVanishingEffectSize = 1e-6;

// The effect strength whose contribution on u has RMS `target` (bisection; delay is not scalable).
EffectBlock SizeEffect(const EffectShape& shape, const HwModel& lin, const Vec& u, double target) {
  const Vec wl = AugmentedModel{lin, {}, 0.0, {}}.simulate(u);
  // The inner state z (before the output map) for state blocks.
  AugmentedModel inner{lin, {}, 0.0, {}};
  inner.nominal.output = StaticMap{};
  const Vec z = inner.simulate(u);
  Vec x = u;
  for (auto& v : x) v = lin.input(v);
  const double force = Rms(LinearBlock{{}, lin.linear.b, 0}.simulate(x));
  const Vec& lv = shape.location == Location::kInput ? u : (shape.location == Location::kOutput ? wl : z);
  Vec du;
  for (std::size_t t = 1; t < u.size(); ++t) du.push_back(std::abs(u[t] - u[t - 1]));
  const double zr = std::max(Rms(z), 1e-12);
  auto rms = [&](double s) {
    return ContributionRms(AugmentedModel{lin, {shape.Block(s, lv, du, force, zr)}, 0.0, {}}, lin, u, nullptr);
  };
  double s = 1.0;
  if (shape.effect != Effect::kDelay && rms(1.0) > target) {
    double lo = 0.0, hi = 1.0;
    for (int it = 0; it < 40; ++it) {
      const double mid = 0.5 * (lo + hi);
      (rms(mid) < target ? lo : hi) = mid;
    }
    s = 0.5 * (lo + hi);
    // Any size of it moves the output by more than the target (a stick-slip cycle in closed loop): the
    // search ends at a vanishing size, which is no effect at all; the draw is not usable.
    if (s < kVanishingEffectSize) throw InputError("open scenario: the effect cannot be sized to its target");
  }
  return shape.Block(s, lv, du, force, zr);
}

// RMS of the part of the true output that the nominal structure (the true system without the effect,
// refitted: linear block, maps, offset, initial state) cannot reproduce on input u (for stiction, nor
// backlash).
double VisibleRms(const AugmentedModel& truth, const Vec& u) {
  const Vec y = truth.simulate(u);
  const Segment s{&u, &y, 0, 0};
  const AugmentedModel nominal = RefitModel(truth.WithoutBlocks(), s, RefitOptions{}).model;
  // The diagnosis also tries one more pole and numerator coefficient: what that absorbs is not visible.
  AugmentedModel richer = truth.WithoutBlocks();
  richer.nominal.linear.a.push_back(0.0);
  richer.nominal.linear.b.push_back(0.0);
  richer = RefitModel(richer, s, RefitOptions{}).model;
  double sse = std::min(SumSquaredError(nominal, s), SumSquaredError(richer, s));
  // Stiction with equal bands is backlash: when every input move is larger than the static band the two
  // give the same signal (the stem never stays stuck where backlash would follow), and what a stiction
  // scenario must show is its stick-slip jump, the part backlash (fitted from the grid and from the
  // kinetic band) cannot absorb.
  if (truth.blocks.size() == 1 && truth.blocks[0].effect == Effect::kStiction) {
    const EffectBlock& b = truth.blocks[0];
    sse = std::min(sse, AddBlock(truth.WithoutBlocks(), Effect::kBacklash, b.location, b.state_variable, s, RefitOptions{}).sse);
    AugmentedModel play = truth;
    play.blocks[0] = {Effect::kBacklash, b.location, {b.params[1]}, b.state_variable};
    sse = std::min(sse, RefitModel(play, s, RefitOptions{}).sse);
  }
  return std::sqrt(sse / y.size());
}

StaticMap RandomMonotoneCubic(Rng& rng, double scale) {
  // v + c2 v^2 + c3 v^3 on |v| <= 3 scale: c3 >= 0 and c2^2 < 3 c3 keep the derivative positive.
  const double c3 = Uniform(rng, 0.03, 0.15) / (scale * scale);
  const double c2 = Uniform(rng, -0.9, 0.9) * std::sqrt(3 * c3) / std::max(scale, 1e-12) * scale;
  return StaticMap::Polynomial({1.0, c2, c3});
}

}  // namespace

std::string InputKindName(InputKind k) {
  switch (k) {
    case InputKind::kMultisine:
      return "multisine";
    case InputKind::kPrbs:
      return "prbs";
    case InputKind::kSteps:
      return "steps";
    case InputKind::kFilteredNoise:
      return "filtered_noise";
    case InputKind::kClosedLoop:
      return "closed_loop";
  }
  return "?";
}

bool OpenScenarioOptions::IsValid(std::string* error) const {
  auto fail = [&](std::string m) {
    if (error) *error = std::move(m);
    return false;
  };
  if (effect != Effect::kNone && !IsDefined(effect, location))
    return fail(fmt::format("{}@{} is not defined", EffectName(effect), LocationName(location)));
  if (!(min_ratio > 0 && max_ratio >= min_ratio)) return fail("0 < min_ratio <= max_ratio required");
  if (min_samples < 200 || max_samples < min_samples) return fail("200 <= min_samples <= max_samples required");
  if (!(offset_probability >= 0 && offset_probability <= 1)) return fail("offset_probability must be in [0, 1]");
  return true;
}

nlohmann::json OpenScenario::Describe() const {
  return {{"effect", truth.Label()},
          {"structure", structure.Text()},
          {"input", InputKindName(input)},
          {"samples", ident.y.size()},
          {"ratio", ratio},
          {"noise_std", noise_std},
          {"u_offset", u_offset},
          {"y_offset", y_offset},
          {"truth", truth.to_json()}};
}

namespace {

// One draw; throws InputError when the draw is unusable (diverged, or the effect invisible).
OpenScenario DrawOpenScenario(const OpenScenarioOptions& o, Rng& rng) {
  OpenScenario sc;
  const std::size_t n = static_cast<std::size_t>(UniformInt(rng, static_cast<int>(o.min_samples), static_cast<int>(o.max_samples)));
  HwModel lin;
  lin.name = "open scenario nominal";
  lin.linear = RandomLinear(rng);
  const int map_kind = UniformInt(rng, 0, 2);  // none, input cubic, output cubic
  sc.input = DrawInputKind(rng);
  if (map_kind == 1) lin.input = RandomMonotoneCubic(rng, 1.0);
  if (map_kind == 2) {
    const Vec z = AugmentedModel{lin, {}, 0.0, {}}.simulate(Standardise(Steps(rng, n)));
    lin.output = RandomMonotoneCubic(rng, std::max(StdDev(z), 1e-6));
  }
  sc.structure.na = static_cast<int>(lin.linear.a.size());
  sc.structure.nb = static_cast<int>(lin.linear.b.size());
  sc.structure.delay = lin.linear.delay;
  sc.structure.input_degree = map_kind == 1 ? 3 : 1;
  sc.structure.output_degree = map_kind == 2 ? 3 : 1;

  EffectShape shape{o.effect, o.location};
  shape.upper = Uniform(rng, 0, 1) < 0.5;
  shape.two_sided = Uniform(rng, 0, 1) < 0.3;
  shape.asymmetry = Uniform(rng, 0.5, 1.0);
  shape.stick_ratio = Uniform(rng, 0.2, 0.8);
  shape.beta = Uniform(rng, 0.1, 0.6);
  shape.delay = UniformInt(rng, 1, 4);
  const double frac = Uniform(rng, 0.02, 0.15);
  const double ratio = Uniform(rng, o.min_ratio, o.max_ratio);
  const bool closed = sc.input == InputKind::kClosedLoop;
  const InputKind open_kind = closed ? InputKind::kSteps : sc.input;
  const double k_loop = closed ? Uniform(rng, 0.2, 0.8) / std::max(std::abs(lin.linear.b[0]) * 4.0, 0.5) : 0.0;
  // Identification and validation excitations (references in closed loop).
  const Vec e_id = OpenLoopInput(open_kind, rng, n), e_va = OpenLoopInput(open_kind, rng, n);
  const AugmentedModel lin_model{lin, {}, 0.0, {}};
  // Inputs for sizing: in closed loop, the loop closed around the linear plant without noise.
  const Vec u_size = closed ? CloseLoop(lin_model, e_id, k_loop, 0.0, rng, nullptr) : e_id;
  double target = frac * std::max(StdDev(lin_model.simulate(u_size)), 1e-9);
  AugmentedModel truth = lin_model;
  double visible = target;  // RMS of what a refit of the nominal cannot absorb
  if (o.effect != Effect::kNone) {
    // The effect's size is what remains after the nominal structure, refitted to the noise-free output,
    // has absorbed what it can (a dead band on a two-level input is only a gain change). Too little
    // left: strengthen once, then give up on this draw.
    for (int attempt = 0; attempt < 2; ++attempt) {
      truth.blocks = {SizeEffect(shape, lin, u_size, target)};
      visible = VisibleRms(truth, u_size);
      const double raw = ContributionRms(truth, lin, u_size, nullptr);
      if (visible >= 0.3 * raw || attempt == 1) break;
      target *= std::min(3.0, 0.3 * raw / std::max(visible, 1e-12));
    }
    if (!(visible > 1e-3 * target))
      throw InputError(fmt::format("open scenario seed {}: the effect is invisible after a nominal refit", o.seed));
  }
  const double noise_guess = visible / ratio;

  auto record = [&](const Vec& excitation, const std::string& name, Vec* contrib) {
    Recording rec;
    rec.name = name;
    std::normal_distribution<double> g(0.0, noise_guess);
    if (closed) {
      rec.u = CloseLoop(truth, excitation, k_loop, noise_guess, rng, &rec.y);
    } else {
      rec.u = excitation;
      rec.y = truth.simulate(rec.u);
      for (auto& v : rec.y) v += g(rng);
    }
    ContributionRms(truth, lin, rec.u, contrib);
    rec.t.resize(rec.u.size());
    for (std::size_t t = 0; t < rec.t.size(); ++t) rec.t[t] = static_cast<double>(t);
    return rec;
  };
  Vec contrib;
  sc.ident = record(e_id, "open scenario identification", &contrib);
  sc.valid = record(e_va, "open scenario validation", nullptr);
  for (const auto* rec : {&sc.ident, &sc.valid})
    for (double v : rec->y)
      if (!std::isfinite(v) || std::abs(v) > 1e6) throw InputError(fmt::format("open scenario seed {}: the system diverged", o.seed));
  sc.noise_std = noise_guess;
  sc.effect_rms = o.effect == Effect::kNone ? 0.0 : visible;
  sc.ratio = sc.effect_rms / noise_guess;
  sc.ident_active.resize(n);
  for (std::size_t t = 0; t < n; ++t) sc.ident_active[t] = o.effect != Effect::kNone && std::abs(contrib[t]) > noise_guess;
  // Operating point: recorded values around u0, y0 far from 0.
  if (Uniform(rng, 0, 1) < o.offset_probability) {
    const double su = StdDev(sc.ident.u), sy = StdDev(sc.ident.y);
    sc.u_offset = (Uniform(rng, 0, 1) < 0.5 ? -1 : 1) * Uniform(rng, 12, 40) * su;
    sc.y_offset = (Uniform(rng, 0, 1) < 0.5 ? -1 : 1) * Uniform(rng, 12, 40) * sy;
    for (auto* rec : {&sc.ident, &sc.valid}) {
      for (auto& v : rec->u) v += sc.u_offset;
      for (auto& v : rec->y) v += sc.y_offset;
    }
  }
  sc.truth = truth;
  sc.nominal = lin_model;
  sc.nominal.output_offset = sc.y_offset;
  return sc;
}

}  // namespace

// Draws tried per seed before the seed is reported unusable (closed-loop stiction often cannot be sized).
constexpr int kMaxDrawsPerSeed = 24;

OpenScenario MakeOpenScenario(const OpenScenarioOptions& o) {
  std::string err;
  if (!o.IsValid(&err)) throw InputError("open scenario: " + err);
  Rng rng(0xd1b54a32d192ed03ULL ^ (static_cast<unsigned long long>(o.seed) * 0x9e3779b97f4a7c15ULL));
  // The same random stream continues after an unusable draw, so the seed alone fixes the scenario.
  for (int attempt = 1;; ++attempt) {
    try {
      return DrawOpenScenario(o, rng);
    } catch (const InputError&) {
      if (attempt == kMaxDrawsPerSeed) throw;
    }
  }
}

}  // namespace hw::diagnose
