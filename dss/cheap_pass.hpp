#pragma once
// Stage 4 of the bound engine: every objective of every live orthant at the cheap (minimal) order, optionally
// repeated in contracted boxes (box contraction, BoundsOptions::contraction_passes).
//
// Deterministic warm starts: per orthant, the first objective not settled before runs first from no blocks (the seed); the other
// objectives start from the blocks the seed found active. Which rows a job starts from therefore never depends
// on which job finished first, so neither do the numbers.
#include <map>
#include <vector>

#include "dss/bound_jobs.hpp"

namespace hw::dss {

// (orthant index, objective index) -> outcome.
using PassOutcomes = std::map<std::pair<int, int>, JobOutcome>;

struct CheapPassOptions {
  int order = 2;
  int contraction_passes = 0;  // see BoundsOptions
  double contraction_min_shrink = 0.05;
  int contraction_max_rounds = 4;
};

struct CheapPassResult {
  PassOutcomes outcomes;  // of the last (uncapped) pass
  int contraction_passes_run = 0;
};

// `settled`: objectives already decided per orthant (dss/edge_witness.hpp); they are not solved and their
// outcomes are returned as given. `witnessed`: per objective index, a value attained by a certified feasible
// point (EdgeWitnessResult::witnessed); a job may end once its bound is beyond it.
CheapPassResult RunCheapPass(const CheapPassOptions& options, EngineContext& ctx,
                             const std::vector<Objective>& objectives, const PassOutcomes& settled,
                             const std::map<int, double>& witnessed, std::vector<OrthantWork>& orthants);

// The value a job of objective j may stop beyond (NaN: none).
double StopBeyond(const std::map<int, double>& witnessed, int j);

// Positions in orthant.rows of the given data rows (rows no longer kept are skipped).
std::vector<int> PositionsOfRows(const OrthantWork& orthant, const std::vector<int>& data_rows);

}  // namespace hw::dss
