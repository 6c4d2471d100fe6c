#pragma once
// A small pool for independent jobs (e.g. one SDP per parameter bound): N jobs over T std::threads,
// each thread taking the next job index from an atomic counter, with a progress callback.
#include <cstddef>
#include <functional>

namespace hw::sdp {

struct JobProgress {
  std::size_t done = 0;
  std::size_t total = 0;
  double elapsed_seconds = 0.0;
  double eta_seconds = 0.0;  // elapsed / done * (total - done); 0 before the first job finishes
};

struct JobPoolOptions {
  int threads = 0;  // 0: std::thread::hardware_concurrency() (at least 1); never more than the jobs
  // Called after each finished job, serialised (never two calls at once), from a worker thread.
  std::function<void(const JobProgress&)> on_progress;
};

// Runs job(i) for i = 0..count-1. Jobs must not depend on each other; each writes only its own outputs.
// If jobs throw, the remaining unstarted jobs are skipped and the first exception is rethrown here after
// every thread has stopped.
void RunJobs(std::size_t count, const std::function<void(std::size_t)>& job, const JobPoolOptions& options = {});

}  // namespace hw::sdp
