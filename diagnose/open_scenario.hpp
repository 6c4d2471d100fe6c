#pragma once
// A second, independent scenario generator for the diagnosis ("open" study): it varies everything the
// first generator (scenario.hpp) keeps fixed, so that a diagnosis tuned on one cannot have learned the
// other.
//
//   linear block  order 1-3 (real poles 0.3-0.97, or a complex pair of radius 0.6-0.97 and angle
//                 0.05-1.2 rad), numerator of 1-3 random coefficients, delay 0-2, DC gain 0.5-2;
//   static maps   none, a monotone cubic input map, or a monotone quadratic/cubic output map;
//   input         multisine, PRBS, random steps, low-pass filtered noise, or a closed loop (proportional
//                 controller on the measured output, reference steps);
//   effect        one of the 14 effect@location rows or none; its contribution to the output has RMS
//                 2-15 % of the output's standard deviation; its *visible* size is the RMS of what a refit
//                 of the nominal structure to the noise-free output cannot absorb, and the noise is that
//                 divided by a ratio drawn in [0.5, 3] (the effect is 0.5-3 noise standard deviations
//                 strong where it can be seen at all);
//   record length 600-1400 samples per recording;
//   offsets       in 40 % of the scenarios u and y are recorded around an operating point 12-40 of their
//                 standard deviations away from 0 (the effects act on the deviations).
// The seed alone fixes the scenario; the effect row is chosen by the caller.
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "diagnose/diagnose.hpp"
#include "diagnose/effects.hpp"
#include "diagnose/nominal_fit.hpp"

namespace hw::diagnose {

enum class InputKind { kMultisine, kPrbs, kSteps, kFilteredNoise, kClosedLoop };
std::string InputKindName(InputKind k);

struct OpenScenarioOptions {
  Effect effect = Effect::kNone;
  Location location = Location::kInput;
  unsigned seed = 1;
  double min_ratio = 0.5, max_ratio = 3.0;  // effect RMS / noise std, drawn uniformly
  std::size_t min_samples = 600, max_samples = 1400;
  double offset_probability = 0.4;
  bool IsValid(std::string* error) const;
};

struct OpenScenario {
  Recording ident, valid;
  AugmentedModel truth;         // in deviation variables (effect block included; none for null scenarios)
  AugmentedModel nominal;       // the true system without the effect, with the operating point as output offset
  NominalSpec structure;        // the nominal's structure (what a user would pass to --fit)
  InputKind input = InputKind::kSteps;
  double ratio = 0.0;           // visible effect RMS / noise std (see above)
  double noise_std = 0.0, effect_rms = 0.0;
  double u_offset = 0.0, y_offset = 0.0;
  std::vector<bool> ident_active;  // |effect contribution| > noise std
  nlohmann::json Describe() const;
};

// Throws InputError on invalid options or when no stable scenario is found for the seed.
OpenScenario MakeOpenScenario(const OpenScenarioOptions& options);

}  // namespace hw::diagnose
