#include "sdp/mpi_executor.hpp"

#include <mpi.h>

#include <deque>
#include <stdexcept>

#include <fmt/format.h>

namespace hw::sdp {
namespace {

constexpr int kTagJob = 1, kTagResult = 2, kTagEnd = 3;

void SendText(const std::string& s, int dest, int tag) {
  MPI_Send(s.data(), static_cast<int>(s.size()), MPI_CHAR, dest, tag, MPI_COMM_WORLD);
}

std::string ReceiveText(const MPI_Status& probed) {
  int count = 0;
  MPI_Get_count(&probed, MPI_CHAR, &count);
  std::string s(static_cast<std::size_t>(count), '\0');
  MPI_Recv(s.data(), count, MPI_CHAR, probed.MPI_SOURCE, probed.MPI_TAG, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
  return s;
}

}  // namespace

MpiExecutor::MpiExecutor() {
  int initialised = 0;
  MPI_Initialized(&initialised);
  if (!initialised) {
    int provided = 0;
    MPI_Init_thread(nullptr, nullptr, MPI_THREAD_FUNNELED, &provided);
  }
  MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
  MPI_Comm_size(MPI_COMM_WORLD, &size_);
}

MpiExecutor::~MpiExecutor() {
  int finalised = 0;
  MPI_Finalized(&finalised);
  if (!finalised) MPI_Finalize();
}

std::shared_ptr<MpiExecutor> MpiExecutor::Instance() {
  static std::shared_ptr<MpiExecutor> instance(new MpiExecutor());
  return instance;
}

int MpiExecutor::workers() const { return size_ > 1 ? size_ - 1 : 1; }

std::vector<JobResult> MpiExecutor::Map(const std::vector<std::string>& specs, const JobFunction& fn,
                                        const JobDone& on_done) {
  if (rank_ != 0) throw std::logic_error("MpiExecutor::Map called on a worker rank");
  if (size_ == 1) return InProcessExecutor().Map(specs, fn, on_done);  // alone: the coordinator does the work
  std::vector<JobResult> out(specs.size());
  std::deque<int> idle;
  for (int r = 1; r < size_; ++r) idle.push_back(r);
  std::vector<long> job_of(static_cast<std::size_t>(size_), -1);
  std::size_t next = 0, done = 0;
  while (done < specs.size()) {
    while (next < specs.size() && !idle.empty()) {
      const int r = idle.front();
      idle.pop_front();
      job_of[static_cast<std::size_t>(r)] = static_cast<long>(next);
      SendText(specs[next++], r, kTagJob);
    }
    MPI_Status st;
    MPI_Probe(MPI_ANY_SOURCE, kTagResult, MPI_COMM_WORLD, &st);
    const std::string msg = ReceiveText(st);
    const auto i = static_cast<std::size_t>(job_of[static_cast<std::size_t>(st.MPI_SOURCE)]);
    out[i] = DecodeJobResult(msg);
    ++done;
    idle.push_back(st.MPI_SOURCE);
    if (on_done) on_done(i, out[i]);
  }
  return out;
}

void MpiExecutor::Serve(const JobFunction& fn) {
  while (true) {
    MPI_Status st;
    MPI_Probe(0, MPI_ANY_TAG, MPI_COMM_WORLD, &st);
    const std::string msg = ReceiveText(st);
    if (st.MPI_TAG == kTagEnd) return;
    SendText(EncodeJobResult(RunJobGuarded(fn, msg)), 0, kTagResult);
  }
}

void MpiExecutor::EndSession() {
  if (rank_ != 0) return;
  for (int r = 1; r < size_; ++r) SendText("", r, kTagEnd);
}

void MpiExecutor::Abort(int code) { MPI_Abort(MPI_COMM_WORLD, code); std::abort(); }

}  // namespace hw::sdp
