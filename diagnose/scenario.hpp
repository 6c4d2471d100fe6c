#pragma once
// Scenario generator for the diagnosis study: a randomised, lightly damped second-order linear system
// (a mass–spring–damper in discrete time, DC gain 1) driven by low-passed random steps, with one
// concealed effect whose contribution to the output has RMS = effect_fraction * std(linear output);
// Gaussian noise of standard deviation (effect RMS) / effect_rms_ratio is added, so the effect is
// only 1.5–3 noise standard deviations strong and not visible by eye in a plot of y.
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "diagnose/diagnose.hpp"
#include "diagnose/effects.hpp"

namespace hw::diagnose {

struct ScenarioOptions {
  Effect effect = Effect::kNone;
  int location = -1;               // -1 = the effect's usual location (see DefaultLocation)
  double effect_rms_ratio = 2.0;   // effect RMS / noise std
  double effect_fraction = 0.0;    // effect RMS / std(linear output); 0 = random in [0.04, 0.08]
  std::size_t samples = 2000;      // per recording (identification and validation each)
  unsigned seed = 1;
  bool IsValid(std::string* error) const;
};

Location DefaultLocation(Effect e);

struct Scenario {
  Recording ident, valid;
  AugmentedModel truth;                     // true system (block none for null scenarios)
  HwModel linear_truth;                     // the same system without the effect
  std::vector<double> ident_contribution;   // w_true - w_linear on the identification input
  std::vector<bool> ident_active;           // |contribution| > noise std
  double noise_std = 0.0, effect_rms = 0.0;
  nlohmann::json truth_json() const;
};

// Throws InputError on invalid options.
Scenario MakeScenario(const ScenarioOptions& options);

}  // namespace hw::diagnose
