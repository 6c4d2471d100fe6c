#pragma once
// The options of a bounds run (dss/set_membership.hpp) and the checks of the settings a person gives, one list
// shared by BoundsOptions::IsValid, the CLI and the Python module.
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "dss/edge_witness_options.hpp"
#include "dss/row_reduction_options.hpp"
#include "pop/constraint_generation.hpp"
#include "sdp/job_executor.hpp"

namespace hw::dss {

struct BoundsOptions {
  int order = 3;                 // delta of the reported intervals
  bool cheap_pass = true;        // solve the minimal order first to skip objectives (recommended)
  bool lp_screen = true;
  // "auto" (the backend per relaxation, SolverForOrder), "csdp", "sdpa" or "dsdp".
  std::string solver = "auto";
  // Local parallel jobs. CSDP and SDPA are not thread-safe, so jobs run in forked worker processes
  // (sdp::ForkExecutor); 0 = one per core. Ignored when `executor` is set.
  int threads = 0;
  // Where jobs run (sdp/job_executor.hpp): null = ForkExecutor(threads); sdp::MpiExecutor for MPI runs.
  std::shared_ptr<sdp::JobExecutor> executor;
  std::string run_dir;           // resumable cache; empty = none
  std::vector<std::string> parameters;  // intervals to compute (names); empty = every parameter
  // Box contraction (bound tightening). The cheap-order bounds of EVERY parameter in an orthant form a box
  // that contains the orthant's part of D^ss(n) inside the prior box, so relaxations in that smaller box bound
  // the same set: they stay valid, are at least as tight, and are far better conditioned (a thin set in a wide
  // box makes the moment matrices nearly singular; docs/setmembership_scale.md). After the first cheap pass,
  // up to `contraction_passes` more cheap passes run in the contracted boxes while some side still moves by
  // more than `contraction_min_shrink` of its width; the full-order pass runs in the last boxes. Only
  // verified bounds contract a box (or any solved bound with verification off). 0 = off (the default: on the
  // paper's example the capped passes contracted too little to pay for themselves; docs/setmembership_scale.md).
  int contraction_passes = 0;
  double contraction_min_shrink = 0.05;
  // Before a full pass above the cheap order, every orthant's box shrinks to its cheap-order bounds (no extra
  // solves: the cheap pass has them) and its rows are reduced again in the new box; the order-delta jobs then
  // run in that box. On the paper's example at 45 dB the cheap bounds are a few hundredths to a few units wide
  // in a box of width 20 (docs/setmembership_scale.md).
  bool contract_before_full_pass = true;
  // Constraint-generation rounds of a job in a contraction pass (every pass but the last): a subset of the
  // data inequalities already gives a valid bound, and the prior box's ill-conditioned LMIs are kept small.
  // The last cheap pass always runs to the full relaxation (generation.max_rounds).
  int contraction_max_rounds = 4;
  // After the last pass, an endpoint whose bound is the verified last iterate of a solve that stopped short (CSDP
  // "partial success", SDPA pFEAS) is solved again in its orthant's box contracted to that pass's verified bounds,
  // up to this many times (dss/refine_pass.hpp); the tighter bound is kept. 0 = off.
  int stopped_short_refinements = 1;
  // Then every endpoint that no certified feasible point reaches, finished or not, is solved again the same way,
  // up to this many times (dss/refine_pass.hpp): the full pass started in boxes contracted to the cheap order's
  // bounds, the refinement runs in boxes contracted to its own. 0 = off (costs one full-order job per endpoint).
  int endpoint_refinements = 0;
  pop::ConstraintGenerationOptions generation;  // its order is set per pass
  RowReductionOptions reduction;           // exact reduction of the data rows (stage 2)
  EdgeWitnessOptions edge_witness;         // endpoints settled by feasible points at the box edge (stage 3)
  // After the last pass, a local search from every solved job's first moments (dss/moment_witness.hpp): more
  // certified feasible points, so the witnessed ranges show how close each endpoint is to the exact interval.
  bool moment_witnesses = true;
  // Progress lines from inside jobs (one per constraint-generation round: working set, status, bound so far).
  // Called in the process that runs the job (a forked worker or an MPI rank); null = silent.
  std::function<void(const std::string&)> round_log;
  bool IsValid(std::string* error) const;
};

// Checks of a bounds run's settings, shared by ComputeBounds, the CLI and the Python module so that each bad
// value gets one message everywhere. Each returns false with the message in *error; the message names the
// setting as the Python keyword (the CLI adds its option's spelling in front).
// (The horizon's check, ValidHorizon, and MinimalOrder are in dss/hw_outer_set.hpp.)
constexpr int kMaxOrder = 20;
// Refinements of every open endpoint (BoundsOptions::endpoint_refinements): 0..kMaxEndpointRefinements.
constexpr int kMaxEndpointRefinements = 10;
// A relaxation order asked for at horizon n: MinimalOrder(n)..kMaxOrder.
bool ValidOrder(int order, int horizon, std::string* error);
// Parallel jobs: 0 (one per core) or more.
bool ValidThreads(int threads, std::string* error);
// Cheap passes in contracted boxes: 0 (no contraction)..10.
bool ValidContractionPasses(int passes, std::string* error);
// Re-solves of an endpoint resting on a solve that stopped short: 0 (never) or more.
bool ValidStoppedShortRefinements(int refinements, std::string* error);
// Re-solves of every open endpoint: 0 (never)..kMaxEndpointRefinements.
bool ValidEndpointRefinements(int refinements, std::string* error);
// The backend of a bounds run: "auto" or a name of sdp::AvailableSolvers().
bool ValidBoundsSolver(const std::string& name, std::string* error);
// The backend that solves the engine's relaxations of this order with data-row blocks capped at
// `block_order_cap` (-1: full order): `name` itself, or for "auto" the one measured best on them (docs/sdp.md):
// CSDP with hwbounds' Schur complement assembly (sdp/csdp_schur.cpp) at every order measured (order 2; order 3
// with 9 x 9 or full 45 x 45 data-row blocks, where it is 2 times faster than DSDP and its bound the tighter).
std::string SolverForOrder(const std::string& name, int order, int block_order_cap = -1);
// Automatic rounds: 0..5 (each round is a full run over the pieces of the shrunk box), and none under the executor
// "mpi", whose worker ranks cannot follow the cuts the coordinator chooses (dss/box_split.hpp).
bool ValidAutoSplitRounds(int rounds, const std::string& executor, std::string* error);

// The settings of a bounds run as a person gives them (the CLI's options, the Python module's keywords). The
// unset ones are not checked (BoundsOptions::IsValid knows no horizon, executor name or automatic cuts).
struct BoundsSettings {
  std::optional<int> horizon;
  std::optional<int> order;  // unset: the minimal order of the horizon
  std::string solver = "auto";
  int threads = 0;
  std::optional<std::string> executor;
  int contraction_passes = 0;
  int row_block_order = -1;  // pop::ConstraintGenerationOptions::block_order_cap
  int stopped_short_refinements = 1;
  int endpoint_refinements = 0;
  std::optional<int> auto_split_rounds;
};
// One check of one setting: the CLI option it belongs to, and the check above that decides it.
struct SettingCheck {
  std::string cli_option;  // e.g. "--threads"
  std::function<bool(std::string*)> valid;
};
// The one list of checks of the given settings, in the order the CLI reports them; the CLI, the Python module and
// BoundsOptions::IsValid run it.
std::vector<SettingCheck> SettingChecks(const BoundsSettings& settings);

}  // namespace hw::dss
