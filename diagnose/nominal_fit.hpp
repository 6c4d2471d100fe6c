#pragma once
// Output-error fit of a nominal structure from several starts, the best kept by held-out error.
//
// Why several starts: with polynomial maps the simulation error has local minima (an output
// polynomial can bend to mimic a wrong linear block), and a diagnosis must not blame an effect for
// what a bad nominal fit caused. Starts (each refined jointly by Levenberg–Marquardt on the fitting
// part of the recording): the linear fit from Steiglitz–McBride and from ARX; for hw structures the
// maps from identity, from least squares on the linear simulation (output map), from an
// over-parametrised Hammerstein least squares at the linear poles (input map), and a few random
// perturbations. The start with the lowest RMS error on the held-out tail wins and is refitted on the
// whole recording; every start is reported.
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "diagnose/effects.hpp"
#include "diagnose/refit.hpp"

namespace hw::diagnose {

// Nominal structures users can ask for instead of a model file.
struct NominalSpec {
  int na = 2, nb = 2, delay = 0;  // linear: z_t = -sum_{1..na} a z + sum_{0..nb-1} b x_{t-delay-j}
  int input_degree = 1;           // hw: polynomial input map of this degree (1 = identity)
  int output_degree = 1;          // hw: polynomial output map of this degree (1 = identity)
  bool IsValid(std::string* error) const;
  std::string Text() const;  // "linear:2,2,0" or "hw:2,2,3,3,0"
  // "linear:NA,NB[,DELAY]" or "hw:NA,NB,PIN,POUT[,DELAY]"; throws InputError.
  static NominalSpec Parse(const std::string& text);
  // The structure of a model (identity or polynomial maps); false for piecewise-linear maps.
  static bool Of(const HwModel& m, NominalSpec* spec);
};

struct NominalFitOptions {
  double holdout_fraction = 1.0 / 3;  // tail used to choose among the starts
  int random_starts = 3;              // hw structures only
  unsigned seed = 1;
  RefitOptions refit;                 // offset and initial state are estimated by default
  bool IsValid(std::string* error) const;
};

struct NominalStart {
  std::string name;
  double fit_rmse = 0.0, holdout_rmse = 0.0;
  nlohmann::json to_json() const { return {{"start", name}, {"fit_rmse", fit_rmse}, {"holdout_rmse", holdout_rmse}}; }
};

struct NominalFit {
  AugmentedModel model;             // no effect blocks; with output offset and initial state
  std::vector<NominalStart> starts;
  int chosen = -1;                  // index into starts
  std::string spec;
  nlohmann::json to_json() const;
  std::string Summary() const;      // one line: structure, chosen start, held-out RMSE
};

// Fits `spec` on data (skip/end as in Segment). Throws InputError when the data are too short.
// `blocks` (effect blocks, e.g. a saturation) are attached to every start and refitted jointly with it,
// so the nominal's numbers are found with the blocks in place rather than bent to imitate them.
NominalFit FitNominal(const NominalSpec& spec, const Segment& data, const NominalFitOptions& options = {},
                      const std::vector<EffectBlock>& blocks = {});

}  // namespace hw::diagnose
