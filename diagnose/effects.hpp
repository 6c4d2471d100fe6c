#pragma once
// Effect blocks that a nominal Hammerstein–Wiener model may have left out, and the "augmented model"
// (nominal model + up to two effect blocks) that the diagnosis simulates and refits.
//
// Locations (where a block sits):
//   input  — on the recorded input u, before the model's input static map (actuator effects);
//   output — on the model's output w + offset, after the output static map (sensor effects; the
//            parameters are therefore in the recording's units);
//   state  — inside the linear recursion on its output z (feedback effects, as in a mass–spring–damper):
//            z*_t = -sum a_i z_{t-i} + sum b_j x_{t-delay-j}, then the block turns z*_t into z_t.
//            The state is a position by default (velocity = z_t - z_{t-1}) or, for force -> velocity
//            drive models, a velocity (velocity = z_t); see StateVariable.
//
// Effect blocks (parameters in the order of EffectBlock::params, physical ranges in brackets):
//   backlash@input        [w >= 0]      play operator of half-width w: x_t = clamp(x_{t-1}, u_t - w, u_t + w)
//   deadzone@input|output [d >= 0, c]   v -> c + sign(v - c) max(|v - c| - d, 0)  (band around c; c optional in JSON, 0)
//   saturation@input|output [lo < hi]   v -> clamp(v, lo, hi) (either limit may be infinite)
//   rate_limit@input      [r > 0]       x_t = x_{t-1} + clamp(u_t - x_{t-1}, -r, r)
//   delay@input           [k >= 1]      dead time: x_t = u_{t-k}, extra to the model's delay (integer)
//   quantization@input|output [q > 0, o]  v -> o + q round((v - o) / q)  (levels o + k q; o optional in JSON, 0)
//   hysteresis@input      [beta >= 0, h >= 0]  x_t = u_t + h s_t, relay s_t = +1 if u_t > beta, -1 if u_t < -beta
//   stiction@input        [fs >= fd >= 0]  stick-slip of a control valve (He et al. 2007): a stuck stem
//                                        moves only once |u_t - x_{t-1}| > fs, then follows u at lag fd
//   coulomb_friction@state [f+ >= 0, f- >= 0]  Coulomb friction with asymmetric levels: the velocity
//                                        update v* is pulled towards 0 by f+ (moving up) or f- (moving
//                                        down) and sticks at 0 when it would cross (no chatter)
//   cubic_stiffness@state [k3]          z_t = z*_t - k3 z_{t-1}^3   (k3 > 0: hardening spring, as in Silverbox)
//   state_saturation@state [lo < hi]    z_t = clamp(z*_t, lo, hi) (a tank that overflows)
// Viscous friction is linear in the velocity and is part of the linear block.
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
  kStiction,
};
enum class Location { kInput, kOutput, kState };
// What the linear block's output z is physically; friction reads its velocity from it.
enum class StateVariable { kPosition, kVelocity };

std::string EffectName(Effect e);
std::string LocationName(Location l);
std::string StateVariableName(StateVariable s);
Effect ParseEffect(const std::string& name);           // throws InputError listing the vocabulary
Location ParseLocation(const std::string& name);       // throws InputError
StateVariable ParseStateVariable(const std::string& name);  // throws InputError
std::vector<std::string> EffectVocabulary();           // every effect name, "none" last
std::vector<std::string> ParameterNames(Effect e);     // names of EffectBlock::params
// Whether a parameter moves the simulation smoothly (refined by Levenberg–Marquardt) or only by a
// search (integer delay, quantization step, relay threshold, stiction bands).
bool ParameterIsSmooth(Effect e, int index);

struct EffectBlock {
  Effect effect = Effect::kNone;
  Location location = Location::kInput;
  std::vector<double> params;
  StateVariable state_variable = StateVariable::kPosition;  // used by state blocks only

  bool IsValid(std::string* error) const;  // includes the physical ranges listed above
  std::string Label() const;               // "effect@location"
  nlohmann::json to_json() const;          // {"effect", "location", "parameters": {name: value}[, "state_variable"]}
  static EffectBlock from_json(const nlohmann::json& j);  // throws InputError (unknown keys included)
};

// Moves parameters into the block's physical range (widths, friction levels, relay height >= 0;
// lower < upper; kinetic <= static band). Used by the optimiser after every step.
void ClampToPhysicalRange(EffectBlock* block);

// The candidate set the diagnosis tries: every (effect, location) pair that is defined.
std::vector<std::pair<Effect, Location>> CandidateEffects();
bool IsDefined(Effect e, Location l);
// "backlash@input,deadzone@output": a subset of CandidateEffects(); throws InputError on an unknown block.
std::vector<std::pair<Effect, Location>> ParseCandidates(const std::string& list);

// Nominal HW model + effect blocks (at most two), an output offset and an initial state.
struct AugmentedModel {
  HwModel nominal;
  std::vector<EffectBlock> blocks;  // input blocks act in order; at most two in all
  double output_offset = 0.0;       // constant added to the output (sensor or operating-point offset)
  // z_{-1}, ..., z_{-na} (the linear block's state before the first sample; past inputs are 0). Empty =
  // from rest.
  std::vector<double> initial_state;
  // Width (in steps) of a smooth rounding used for output quantizers while an optimiser moves the other
  // numbers (0: the exact staircase). Never written or read: a fitting aid only (see refit.cpp).
  double output_quantizer_smoothing = 0.0;
  double input_quantizer_smoothing = 0.0;  // the same for input quantizers

  bool has_block() const { return !blocks.empty(); }
  Effect effect() const { return blocks.empty() ? Effect::kNone : blocks.front().effect; }
  std::string Label() const;  // "none", "backlash@input" or "backlash@input+coulomb_friction@state"
  // Noise-free output for input u. Returns false (and fills with a large value) when the recursion
  // diverges, so that an optimiser sees a bad but finite cost.
  bool simulate(const std::vector<double>& u, std::vector<double>* y) const;
  std::vector<double> simulate(const std::vector<double>& u) const;
  // Input u after the input-location blocks, in order: the signal the input map sees.
  std::vector<double> AfterInputBlocks(const std::vector<double>& u) const;
  AugmentedModel WithoutBlocks() const;  // same numbers, blocks switched off
  nlohmann::json to_json() const;
  // Reads a plain model JSON or an augmented one (docs/input_output.md "Model JSON" + the keys above). Unknown or
  // misspelt keys are an error naming the key. Throws InputError.
  static AugmentedModel from_json(const nlohmann::json& j);
  static AugmentedModel Load(const std::string& path);  // errors name the file
};

// A block's parameters in the recording's units: a state saturation's limits act on z, which the output
// map and the offset turn into the recorded value; every other block's parameters are already in the
// units of the signal it acts on (u for input blocks, the recorded y for output blocks).
std::vector<double> ParametersInRecordingUnits(const EffectBlock& block, const AugmentedModel& model);
std::string ParameterText(const EffectBlock& block, const AugmentedModel& model);  // "lower = 3, upper = 9.95"
// Coulomb friction levels as forces in the input's units: a level is a velocity change per step, the
// input moves the velocity by sum(b) per unit per step (identity input map). Empty for other blocks.
std::vector<double> FrictionLevelsInInputUnits(const EffectBlock& block, const AugmentedModel& model);

// Stiction's bands are compared with |u_t - x_{t-1}| up to this tolerance relative to |u_t| + |x_{t-1}| +
// static band: a difference within it of a band is not beyond the band (a moving stem sits exactly the
// kinetic band behind the input, so a hold must stop it independently of rounding).
inline constexpr double kStictionBandTolerance = 1e-9;
// Applies a memoryful or static input-location block to a signal (exposed for tests and the generator).
std::vector<double> ApplyInputBlock(const EffectBlock& block, const std::vector<double>& u);
// Deadzone, saturation, quantization; `smoothing` > 0 rounds a quantizer smoothly (width in steps).
double ApplyStaticBlock(const EffectBlock& block, double v, double smoothing = 0.0);

}  // namespace hw::diagnose
