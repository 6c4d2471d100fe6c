#pragma once
// Where independent SDP jobs run. CSDP and SDPA keep process-wide state (docs/sdp.md), so two solves in one
// process are serialised; using both cores, or many machines, needs several processes. Jobs are therefore
// described and answered as text (JSON in practice): the same job function serves
//   - InProcessExecutor: the calling process, sequentially (reference; debugging);
//   - ForkExecutor:      forked local worker processes, one per job, `workers` at a time;
//   - MpiExecutor:       MPI ranks (sdp/mpi_executor.hpp), rank 0 coordinating, for one or many machines.
// A job that crashes its process (CSDP calls exit() on some errors) comes back as a failed JobResult with the
// reason; it never takes the run down and is never silently lost. When Map itself ends by an exception (from
// on_done or the interrupt check), no worker process is left behind.
#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace hw::sdp {

struct JobResult {
  bool ok = false;
  std::string text;   // the job function's answer when ok
  std::string error;  // why not, otherwise (exception text, exit status, signal)
};

using JobFunction = std::function<std::string(const std::string& spec)>;

// Runs fn(spec), turning an exception into a failed result (shared by every executor).
JobResult RunJobGuarded(const JobFunction& fn, const std::string& spec);
// Wire format of a result between processes: 'O' + text or 'E' + error.
std::string EncodeJobResult(const JobResult& r);
JobResult DecodeJobResult(const std::string& message);
// Called in the coordinating process after each job, serialised, with the job's index in the batch.
using JobDone = std::function<void(std::size_t index, const JobResult& result)>;

class JobExecutor {
 public:
  virtual ~JobExecutor() = default;
  virtual std::string name() const = 0;
  virtual int workers() const = 0;
  // Runs fn on every spec and returns the results in the order of `specs`.
  virtual std::vector<JobResult> Map(const std::vector<std::string>& specs, const JobFunction& fn,
                                     const JobDone& on_done = {}) = 0;
  // False on MPI worker ranks: they call Serve(fn) where the coordinator calls Map.
  virtual bool is_coordinator() const { return true; }
  // Worker side: answers jobs with fn until the coordinator calls EndSession().
  virtual void Serve(const JobFunction& fn) { (void)fn; }
  // Coordinator side: releases the workers' Serve() (one session = one engine run).
  virtual void EndSession() {}
  // Called on the coordinating side while Map runs: before each job in process, and at least every 100 ms
  // while waiting for forked workers. An exception it throws ends Map (forked workers still running are
  // killed and reaped first) and propagates: an embedding host stops a run this way (Python's Ctrl-C).
  void set_interrupt_check(std::function<void()> check) { interrupt_check_ = std::move(check); }

 protected:
  std::function<void()> interrupt_check_;
};

class InProcessExecutor : public JobExecutor {
 public:
  std::string name() const override { return "in-process"; }
  int workers() const override { return 1; }
  std::vector<JobResult> Map(const std::vector<std::string>& specs, const JobFunction& fn,
                             const JobDone& on_done = {}) override;
};

class ForkExecutor : public JobExecutor {
 public:
  explicit ForkExecutor(int workers);  // workers <= 0: one per core
  std::string name() const override { return "fork"; }
  int workers() const override { return workers_; }
  std::vector<JobResult> Map(const std::vector<std::string>& specs, const JobFunction& fn,
                             const JobDone& on_done = {}) override;

 private:
  int workers_;
};

// "inprocess", "fork" (workers processes) or, when built with MPI, "mpi" (MPI_COMM_WORLD).
std::shared_ptr<JobExecutor> MakeExecutor(const std::string& kind, int workers);
// True for "inprocess", "fork" or "mpi"; otherwise false with "executor 'NAME' unknown; expected ..." in *error.
// (Whether this build has MPI is MakeExecutor's to say.)
bool ValidExecutorName(const std::string& kind, std::string* error);

}  // namespace hw::sdp
