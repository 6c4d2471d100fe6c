#pragma once
// The job function of a bounds run: the jobs of the bound engine, as text, so that one function answers them in
// this process, in forked workers or on other MPI ranks (sdp/job_executor.hpp). A job depends only on (settings,
// set) and its spec, never on which worker runs it or when, so results do not depend on timing. Each kind is owned
// by its stage's file, which implements its handler (JobHandler, dss/job_context.hpp):
//   {"kind": "lp", "l"}                          LP screen of orthant l (emptiness, verified;
//                                                dss/orthant_screen.hpp);
//   {"kind": "reduce", "l", "box", ["step"]}     exact row reduction of orthant l's data rows of horizon step
//                                                `step` (all steps without it; dss/row_reduction.hpp);
//   {"kind": "witness", "l", "param", "dir", "starts", "rows"}
//                                                a feasible local extreme of a parameter over orthant l, from the
//                                                starts in turn, over the data rows `rows` (dss/edge_witness.hpp);
//   {"kind": "relax", "l", "param", "dir", "d", "box", "rows", "initial", ["max_rounds"], ["stop_beyond"]}
//                                                bound min (dir -1) / max (+1) of a parameter over orthant l at
//                                                order d in `box`, over the data rows `rows`, starting with blocks
//                                                for `initial` (indices into rows); it may end once its bound
//                                                is beyond stop_beyond (a value attained elsewhere;
//                                                dss/relax_job.hpp).
// A spec of an unknown kind is an error of the job, never answered by another kind.
#include "dss/engine_settings.hpp"
#include "dss/hw_outer_set.hpp"
#include "sdp/job_executor.hpp"

namespace hw::dss {

// Answers job specs for (settings, set) by their "kind"; see JobContext for what is built once per process.
sdp::JobFunction MakeJobFunction(const EngineSettings& settings, const HwOuterSet& set);

}  // namespace hw::dss
