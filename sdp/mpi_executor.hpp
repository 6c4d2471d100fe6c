#pragma once
// Independent SDP jobs over MPI (Open MPI from Debian): the same run on one machine or many.
//   mpirun -np 3 hwbounds bounds ... --executor mpi
// Every rank runs the same program on the same inputs; rank 0 coordinates (builds the job list, keeps the run
// directory, aggregates) and ranks 1..P-1 answer jobs. Jobs and answers are text, as for ForkExecutor. One
// engine run is one session: the coordinator ends it with EndSession(), which releases the workers' Serve().
// Built only when CMake finds MPI (HW_HAVE_MPI).
#include <memory>

#include "sdp/job_executor.hpp"

namespace hw::sdp {

class MpiExecutor : public JobExecutor {
 public:
  // Initialises MPI on first use; MPI_Finalize runs at exit (worker ranks get an end message first).
  static std::shared_ptr<MpiExecutor> Instance();
  ~MpiExecutor() override;
  std::string name() const override { return "mpi"; }
  int workers() const override;  // ranks answering jobs (size - 1; the coordinator itself when alone)
  int rank() const { return rank_; }
  int size() const { return size_; }
  bool is_coordinator() const override { return rank_ == 0; }
  std::vector<JobResult> Map(const std::vector<std::string>& specs, const JobFunction& fn,
                             const JobDone& on_done = {}) override;
  void Serve(const JobFunction& fn) override;
  void EndSession() override;
  // Stops every worker for good and aborts the MPI job (used when the coordinator fails).
  [[noreturn]] void Abort(int code);

 private:
  MpiExecutor();
  int rank_ = 0, size_ = 1;
};

}  // namespace hw::sdp
