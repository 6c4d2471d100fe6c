#pragma once
// Guaranteed parameter intervals of a Hammerstein–Wiener model over D^ss(n) (paper 001, eqs. 22-33).
//
// The engine is a pipeline of stages, each in its own file (docs/setmembership.md, "How the bounds are computed"):
//  1. screen orthants   (dss/orthant_screen.hpp): an LP per sign orthant; infeasible (verified) => empty.
//  2. reduce rows       (dss/row_reduction.hpp):  drop data rows implied by the others (exact at any order).
//  3. edge witnesses    (dss/edge_witness.hpp):   endpoints at the prior box edge settled by feasible points.
//  4. cheap pass        (dss/cheap_pass.hpp):     every objective of every live orthant at the minimal order.
//  5. full pass         (dss/full_pass.hpp):      the wanted objectives at order delta, skipping orthants
//                                                 whose cheap bound cannot move the interval (Property 3).
//  6. refine            (dss/refine_pass.hpp):    endpoints of solves that stopped short, in contracted boxes.
//  7. moment witnesses  (dss/moment_witness.hpp): feasible points where the relaxations' moments point.
//  8. aggregate         (dss/aggregate.hpp):      min/max over orthants, fallbacks, the prior box.
// Every relaxation job (dss/relax_job.hpp) solves by constraint generation over the kept rows
// (pop/constraint_generation.hpp): rows enter as scalar moment constraints and get their localizing block
// when violated; every round's multiplier yields a verified bound, so a solve that stops short still bounds.
// The core behind this header: the options become the stages' own (dss/engine_setup.hpp, once per run); the
// stages share an EngineContext (dss/engine_context.hpp: settings, set, executor, run cache, counters, progress)
// and hand on one PipelineState (dss/pipeline_state.hpp); jobs go through the run cache (dss/run_cache.hpp) to the
// executor (dss/job_dispatch.hpp), and each job kind is answered by its stage's handler (dss/job_function.hpp).
// No stage includes this header or the options' (dss/bounds_options.hpp).
// Guarantees: every reported endpoint is a valid bound of D^ss(n) intersected with the prior box. A failed
// solve never disappears: the endpoint falls back to the same orthant's cheap-order bound, or to the box edge,
// and is marked "conservative"; an orthant is discarded only on a verified certificate.
#include <functional>

#include "dss/bounds_options.hpp"
#include "dss/bounds_summary.hpp"
#include "dss/box_split.hpp"
#include "dss/hw_outer_set.hpp"

namespace hw::dss {

BoundsSummary ComputeBounds(const BoundsOptions& options, const HwOuterSet& set,
                            const std::function<void(const BoundsProgress&)>& progress = {});

// ComputeBounds in each piece of set.box() cut at `cuts`, combined (dss/box_split.hpp, BoundsInPieces). No cut:
// ComputeBounds itself.
BoundsSummary ComputeBoundsInPieces(const BoundsOptions& options, const HwOuterSet& set,
                                    const std::vector<BoxCut>& cuts,
                                    const std::function<void(const BoundsProgress&)>& progress = {});

// ComputeBoundsInPieces, then up to auto_split.rounds rounds of automatic cuts (dss/box_split.hpp,
// BoundsWithAutoSplit). Not under an MPI executor.
BoundsSummary ComputeBoundsWithAutoSplit(const BoundsOptions& options, const HwOuterSet& set,
                                         const std::vector<BoxCut>& cuts, const AutoSplitOptions& auto_split,
                                         const std::function<void(const BoundsProgress&)>& progress = {});

}  // namespace hw::dss
