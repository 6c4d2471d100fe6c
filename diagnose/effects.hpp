#pragma once
// Effect blocks that a nominal Hammerstein–Wiener model may have left out, and the "augmented model"
// (nominal model + one effect block at one location) that the diagnosis simulates and refits.
//
// Locations (where the block sits):
//   input  — on the recorded input u, before the model's input static map (actuator effects);
//   output — on the model's output w, after the output static map (sensor effects);
//   state  — inside the linear recursion on its output z (feedback effects, as in a mass–spring–damper):
//            z_t = -sum a_i z_{t-i} + sum b_j x_{t-delay-j} + phi(z_{t-1}, z_{t-2}).
//
// Effect blocks (parameters in the order of EffectBlock::params):
//   backlash@input        [w]        play operator of half-width w: x_t = clamp(x_{t-1}, u_t - w, u_t + w)
//   deadzone@input|output [d]        v -> sign(v) max(|v| - d, 0)
//   saturation@input|output [lo, hi] v -> clamp(v, lo, hi)
//   rate_limit@input      [r]        x_t = x_{t-1} + clamp(u_t - x_{t-1}, -r, r)
//   delay@input           [k]        x_t = u_{t-k}, k >= 1 extra samples (integer)
//   quantization@input|output [q]    v -> q round(v / q)
//   hysteresis@input      [beta, h]  x_t = u_t + h s_t, relay s_t = +1 if u_t > beta, -1 if u_t < -beta, else s_{t-1}
//   coulomb_friction@state [fc]      phi = -fc sign(z_{t-1} - z_{t-2})
//   cubic_stiffness@state [k3]       phi = -k3 z_{t-1}^3   (k3 > 0: hardening spring, as in Silverbox)
//   state_saturation@state [lo, hi]  z_t is clamped to [lo, hi] inside the recursion (a tank that overflows)
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/hw_model.hpp"

namespace hw::diagnose {

enum class Effect {
  kNone,
  kBacklash,
  kDeadzone,
  kSaturation,
  kRateLimit,
  kDelay,
  kQuantization,
  kCoulombFriction,
  kHysteresis,
  kCubicStiffness,
  kStateSaturation,
};
enum class Location { kInput, kOutput, kState };

std::string EffectName(Effect e);
std::string LocationName(Location l);
Effect ParseEffect(const std::string& name);        // throws InputError listing the vocabulary
Location ParseLocation(const std::string& name);    // throws InputError
std::vector<std::string> EffectVocabulary();        // every effect name, "none" last
std::vector<std::string> ParameterNames(Effect e);  // names of EffectBlock::params
// Whether a parameter moves the simulation smoothly (refined by Levenberg–Marquardt) or only by a
// search (integer delay, quantization step, relay threshold).
bool ParameterIsSmooth(Effect e, int index);

struct EffectBlock {
  Effect effect = Effect::kNone;
  Location location = Location::kInput;
  std::vector<double> params;

  bool IsValid(std::string* error) const;
  nlohmann::json to_json() const;  // {"effect", "location", "parameters": {name: value}}
};

// The candidate set the diagnosis tries: every (effect, location) pair that is defined.
std::vector<std::pair<Effect, Location>> CandidateEffects();
// "backlash@input,deadzone@output": a subset of CandidateEffects(); throws InputError on an unknown block.
std::vector<std::pair<Effect, Location>> ParseCandidates(const std::string& list);

// Nominal HW model + one effect block.
struct AugmentedModel {
  HwModel nominal;
  EffectBlock block;
  double output_offset = 0.0;  // constant added to the output (sensor or operating-point offset)

  // Noise-free output for input u, simulated from rest. Returns false (and fills with a large
  // value) when the recursion diverges, so that an optimiser sees a bad but finite cost.
  bool simulate(const std::vector<double>& u, std::vector<double>* y) const;
  std::vector<double> simulate(const std::vector<double>& u) const;
  nlohmann::json to_json() const;
  static AugmentedModel from_json(const nlohmann::json& j);  // throws InputError
};

// Applies a memoryful or static input-location block to a signal (exposed for tests and the generator).
std::vector<double> ApplyInputBlock(const EffectBlock& block, const std::vector<double>& u);
double ApplyStaticBlock(const EffectBlock& block, double v);  // deadzone, saturation, quantization

}  // namespace hw::diagnose
