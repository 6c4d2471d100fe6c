#pragma once
// The job function of a bounds run: one handler per job kind, each owned by its stage's file (JobHandler in
// dss/bound_jobs.hpp). A spec of an unknown kind is an error of the job, never answered by another kind.
#include "dss/bound_jobs.hpp"
#include "sdp/job_executor.hpp"

namespace hw::dss {

// Answers job specs for (options, set) by their "kind"; see JobContext for what is built once per process.
sdp::JobFunction MakeJobFunction(const BoundsOptions& options, const HwOuterSet& set);

}  // namespace hw::dss
