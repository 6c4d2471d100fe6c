#include "sdp/job_pool.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

namespace hw::sdp {

void RunJobs(std::size_t count, const std::function<void(std::size_t)>& job, const JobPoolOptions& options) {
  if (count == 0) return;
  std::size_t threads = options.threads > 0 ? static_cast<std::size_t>(options.threads)
                                            : std::max(1u, std::thread::hardware_concurrency());
  threads = std::min(threads, count);
  const auto start = std::chrono::steady_clock::now();
  std::atomic<std::size_t> next{0};
  std::atomic<bool> failed{false};
  std::mutex mu;  // guards done, first_error and the progress callback
  std::size_t done = 0;
  std::exception_ptr first_error;

  auto worker = [&] {
    while (!failed.load()) {
      const std::size_t i = next.fetch_add(1);
      if (i >= count) return;
      try {
        job(i);
        std::lock_guard<std::mutex> lock(mu);
        ++done;
        if (options.on_progress) {
          JobProgress p;
          p.done = done;
          p.total = count;
          p.elapsed_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
          p.eta_seconds = p.elapsed_seconds / static_cast<double>(done) * static_cast<double>(count - done);
          options.on_progress(p);
        }
      } catch (...) {  // from the job or the callback; never let it escape a std::thread
        std::lock_guard<std::mutex> lock(mu);
        if (!first_error) first_error = std::current_exception();
        failed = true;
        return;
      }
    }
  };
  if (threads == 1) {
    worker();
  } else {
    std::vector<std::thread> pool;
    pool.reserve(threads);
    for (std::size_t t = 0; t < threads; ++t) pool.emplace_back(worker);
    for (auto& t : pool) t.join();
  }
  if (first_error) std::rethrow_exception(first_error);
}

}  // namespace hw::sdp
