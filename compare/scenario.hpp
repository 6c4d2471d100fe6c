#pragma once
// Comparison scenarios: one plant, one noise level, and the experiment each method gets on it.
//
// Scenario JSON (`hwbounds compare --scenario file.json`; the built-ins are written in the same form):
// {
//   "name": "my_plant",
//   "plant": "hw" | "backlash" | "valve",
//   "model": {...project model JSON...} or "model_file": "path.json",      (plant "hw")
//   "output_inverse_polynomial": [1, 0.8, 3.2],  (optional, plant "hw": w solves z = sum c_k w^k)
//   "system": {...Brouri system JSON...},                                  (plant "backlash")
//   "input_range": [-10, 10],
//   "noise": {"snr_db": 31} | {"bound": 0.05}     (uniform in [-bound, bound]; plant "hw")
//            {"std": 0.01}                        (Gaussian; plant "backlash")
//   "setmembership": {"samples": 100, "horizon": 1, "order": 1, "parameters": ["a1", ...],
//                     "box": 10 | [[lo, hi], ...], "solver": "auto"},
//   "esmaeilani": {"segments": 2, "samples": 300, "hold": [3, 15], "grid_f": 12, "grid_g": 12,
//                  "max_iterations": 100},
//   "validation": {"samples": 500, "hold": [1, 10]},
//   "brouri": {"periods": 50, "samples_per_period": 512, "omegas": [0.01, ...]}
// }
// Unknown keys are errors (a misspelt option must not silently fall back to a default).
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "compare/plant.hpp"
#include "dss/hw_outer_set.hpp"
#include "estimators/brouri/system.hpp"

namespace hw::compare {

enum class PlantKind { kDiscreteHw, kValve, kBacklash };
const char* ToString(PlantKind k);

struct SetMembershipExperiment {
  int samples = 100;  // random input, uniform over input_range
  int horizon = 1;    // n
  int order = 1;      // delta
  std::vector<std::string> parameters;  // empty = all (needed for the point estimate's curves)
  std::vector<std::pair<double, double>> box;  // prior box; empty = +-box_half_width
  double box_half_width = 10.0;
  std::string solver = "auto";
  // Cheap passes repeated in each orthant's contracted box (BoundsOptions::contraction_passes, 0..10).
  int contract_passes = 0;
};
struct EsmaeilaniExperiment {
  int segments = 2;
  int samples = 300;          // per segment ("operating record": random levels held hold_min..hold_max)
  int hold_min = 3, hold_max = 15;
  int grid_f = 12, grid_g = 12;
  int max_iterations = 100;
};
struct ValidationExperiment {
  int samples = 500;  // random levels held hold_min..hold_max, noise-free truth as reference
  int hold_min = 1, hold_max = 10;
};
struct BrouriExperiment {
  int periods = 50;
  int samples_per_period = 512;
  std::vector<double> omegas;  // empty = the paper's
};

struct Scenario {
  std::string name, description;
  PlantKind kind = PlantKind::kDiscreteHw;
  Plant plant;                         // truth (kDiscreteHw, kValve)
  brouri::BacklashHwSystem backlash;   // truth (kBacklash)
  double input_lo = -10.0, input_hi = 10.0;
  double snr_db = 31.0;       // kDiscreteHw: noise bound from the SNR of the set-membership record ...
  double noise_bound = 0.0;   // ... unless a bound is given
  SetMembershipExperiment setmembership;
  EsmaeilaniExperiment esmaeilani;
  ValidationExperiment validation;
  BrouriExperiment brouri;

  bool IsValid(std::string* error) const;
  nlohmann::json to_json() const;
  static Scenario FromJson(const nlohmann::json& j, const std::string& source);  // throws InputError
};

std::vector<std::string> BuiltinScenarioNames();  // setmembership-example, brouri-backlash, valve
// A built-in name or a JSON file path.
Scenario LoadScenario(const std::string& name_or_path);

// The truth in paper 001's parametrisation (gamma_1 = alpha_1 = 1), or why the plant is outside its class.
struct SetMembershipClass {
  bool ok = false;
  std::string reason;
  dss::HwStructure structure;
  std::vector<double> theta;  // layout of dss::MakeLayout(structure)
  std::vector<std::string> names;
};
SetMembershipClass SetMembershipTruth(const Plant& plant);

struct Applicability {
  bool applies = false;
  std::string reason;      // why not, when it does not
  std::string experiment;  // what the method is given, when it does
};
const std::vector<std::string>& AllMethods();  // setmembership, brouri, esmaeilani
Applicability MethodApplies(const Scenario& s, const std::string& method);

}  // namespace hw::compare
