#pragma once
// Stage 4 of the bound engine: every objective of every live orthant at the cheap (minimal) order, optionally
// repeated in contracted boxes (box contraction, BoundsOptions::contraction_passes).
//
// Deterministic warm starts: per orthant, the first objective not settled before runs first from no blocks (the seed); the other
// objectives start from the blocks the seed found active. Which rows a job starts from therefore never depends
// on which job finished first, so neither do the numbers.
#include <map>
#include <vector>

#include "dss/pipeline_state.hpp"
#include "dss/relax_job.hpp"

namespace hw::dss {

struct CheapPassOptions {
  int order = 2;
  int contraction_passes = 0;  // see BoundsOptions
  double contraction_min_shrink = 0.05;
  int contraction_max_rounds = 4;
};

struct CheapPassResult {
  int contraction_passes_run = 0;
};

// Sets state.cheap to the outcomes of the last (uncapped) pass. The objectives in state.settled (dss/edge_witness.hpp)
// are not solved: their outcomes are taken as given. state.witnessed: per objective index, a value attained by a
// certified feasible point; a job may end once its bound is beyond it.
CheapPassResult RunCheapPass(const CheapPassOptions& options, EngineContext& ctx, PipelineState& state);

// The value a job of objective j may stop beyond (NaN: none).
double StopBeyond(const std::map<int, double>& witnessed, int j);

// Positions in orthant.rows of the given data rows (rows no longer kept are skipped).
std::vector<int> PositionsOfRows(const OrthantWork& orthant, const std::vector<int>& data_rows);

}  // namespace hw::dss
