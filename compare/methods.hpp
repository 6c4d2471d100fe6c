#pragma once
// One Monte Carlo run of a comparison study: every selected method on its own experiment on the same
// plant and noise level, then the normalisation-free quantities (plant.hpp) and, for the set-membership
// method, coverage of the truth and whether the other methods' point estimates lie in its intervals.
//
// Seeds: run r of a study with seed S uses S + r for its records; the validation record is common to
// every run and method of a study (seed S). Per-run JSON schema: docs/compare.md.
#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "compare/scenario.hpp"

namespace hw::compare {

// How a method's run ended, as a run record's "status" stores it.
enum class MethodStatus { kOk, kFailed };
std::string ToString(MethodStatus status);
// The status a run record holds; a record without one, or with an unknown one, counts as failed.
MethodStatus MethodStatusOf(const nlohmann::json& record);

struct Record {
  std::vector<double> u, w, y;  // input, noise-free output, measured output
};

// Random levels uniform over the input range held a random number of samples in [hold_min, hold_max],
// the plant started in the steady state of the first level; y = w + uniform(-bound, bound).
Record OperatingRecord(const Plant& plant, double lo, double hi, int samples, int hold_min, int hold_max,
                       double bound, std::uint64_t seed);
// Paper 001's experiment: u uniform in [lo, hi] per sample, plant from rest, bounded uniform noise. For
// the set-membership example this reproduces core's SimulateCeroneExample sample for sample (same draws).
// bound <= 0: the bound is set from snr_db (E eta^2 = bound^2 / 3).
Record RandomInputRecord(const Plant& plant, double lo, double hi, int samples, double snr_db, double bound,
                         std::uint64_t seed, double* bound_used);

// The common validation record of a study (input and noise-free true output).
Record ValidationRecord(const Scenario& s, std::uint64_t study_seed);

// Runs `methods` (each applicable or reported as not applicable) for run `run`; returns the per-run JSON.
nlohmann::json RunOne(const Scenario& s, const std::vector<std::string>& methods, int run, std::uint64_t study_seed);

// The truth's normalisation-free curves (for plots and the summary).
nlohmann::json TruthCurves(const Scenario& s);

}  // namespace hw::compare
