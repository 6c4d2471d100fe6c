#include "sdp/job_executor.hpp"

#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <map>
#include <stdexcept>
#include <thread>

#include <fmt/format.h>

#include "core/worker_process.hpp"

#ifdef HW_HAVE_MPI
#include "sdp/mpi_executor.hpp"
#endif

namespace hw::sdp {
namespace {

bool WriteAll(int fd, const char* p, std::size_t n) {
  while (n > 0) {
    const ssize_t w = ::write(fd, p, n);
    if (w < 0) {
      if (errno == EINTR) continue;
      return false;
    }
    p += w;
    n -= static_cast<std::size_t>(w);
  }
  return true;
}

struct Child {
  pid_t pid = -1;
  int fd = -1;
  std::size_t index = 0;
  std::string buffer;
};

// The child's answer on the pipe: one byte 'O' (ok) or 'E' (error), then the text.
JobResult Decode(const Child& c, int wait_status) {
  JobResult r;
  if (WIFSIGNALED(wait_status)) {
    r.error = fmt::format("worker process killed by signal {} ({})", WTERMSIG(wait_status), strsignal(WTERMSIG(wait_status)));
    return r;
  }
  if (WIFEXITED(wait_status) && WEXITSTATUS(wait_status) != 0) {
    r.error = fmt::format("worker process exited with status {} (a solver library called exit())",
                          WEXITSTATUS(wait_status));
    return r;
  }
  if (c.buffer.empty()) {
    r.error = "worker process ended without an answer";
    return r;
  }
  return DecodeJobResult(c.buffer);
}

}  // namespace

JobResult RunJobGuarded(const JobFunction& fn, const std::string& spec) {
  JobResult r;
  try {
    r.text = fn(spec);
    r.ok = true;
  } catch (const std::exception& e) {
    r.error = e.what();
  } catch (...) {
    r.error = "unknown exception";
  }
  return r;
}

std::string EncodeJobResult(const JobResult& r) { return (r.ok ? "O" : "E") + (r.ok ? r.text : r.error); }

JobResult DecodeJobResult(const std::string& message) {
  JobResult r;
  if (message.empty()) {
    r.error = "empty answer from a worker";
    return r;
  }
  r.ok = message[0] == 'O';
  (r.ok ? r.text : r.error) = message.substr(1);
  return r;
}

std::vector<JobResult> InProcessExecutor::Map(const std::vector<std::string>& specs, const JobFunction& fn,
                                              const JobDone& on_done) {
  std::vector<JobResult> out(specs.size());
  for (std::size_t i = 0; i < specs.size(); ++i) {
    if (interrupt_check_) interrupt_check_();
    out[i] = RunJobGuarded(fn, specs[i]);
    if (on_done) on_done(i, out[i]);
  }
  return out;
}

ForkExecutor::ForkExecutor(int workers)
    : workers_(workers > 0 ? workers : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()))) {}

std::vector<JobResult> ForkExecutor::Map(const std::vector<std::string>& specs, const JobFunction& fn,
                                         const JobDone& on_done) {
  std::vector<JobResult> out(specs.size());
  std::map<int, Child> running;  // by read fd
  // Map left by an exception (on_done, the interrupt check, fork failure): kill and reap every worker.
  struct KillOnUnwind {
    std::map<int, Child>& running;
    ~KillOnUnwind() {
      for (auto& [fd, c] : running) {
        ::kill(c.pid, SIGKILL);
        ::close(fd);
        while (::waitpid(c.pid, nullptr, 0) < 0 && errno == EINTR) {
        }
      }
    }
  } kill_on_unwind{running};
  std::size_t next = 0;
  std::fflush(nullptr);  // buffered output must not be duplicated into the children
  const pid_t parent = ::getpid();
  // On an exception here (fork failure, a throwing on_done) no child is left running or unreaped.
  struct Reaper {
    std::map<int, Child>& running;
    ~Reaper() {
      for (auto& [fd, c] : running) {
        ::kill(c.pid, SIGKILL);
        ::close(fd);
        while (::waitpid(c.pid, nullptr, 0) < 0 && errno == EINTR) {
        }
      }
    }
  } reaper{running};
  auto launch = [&](std::size_t i) {
    int fds[2];
    if (::pipe(fds) != 0) throw std::runtime_error(fmt::format("pipe: {}", std::strerror(errno)));
    const pid_t pid = ::fork();
    if (pid < 0) throw std::runtime_error(fmt::format("fork: {}", std::strerror(errno)));
    if (pid == 0) {
      EndWithParent(parent);
      ::close(fds[0]);
      const JobResult r = RunJobGuarded(fn, specs[i]);
      const std::string msg = EncodeJobResult(r);
      const bool written = WriteAll(fds[1], msg.data(), msg.size());
      ::close(fds[1]);
      ::_exit(written ? 0 : 3);  // no atexit handlers, no flushing of the parent's buffers
    }
    ::close(fds[1]);
    running[fds[0]] = {pid, fds[0], i, {}};
  };
  while (next < specs.size() || !running.empty()) {
    while (next < specs.size() && static_cast<int>(running.size()) < workers_) launch(next++);
    std::vector<pollfd> polls;
    for (const auto& [fd, c] : running) polls.push_back({fd, POLLIN, 0});
    const int ready = ::poll(polls.data(), polls.size(), interrupt_check_ ? 100 : -1);
    if (interrupt_check_) interrupt_check_();
    if (ready < 0) {
      if (errno == EINTR) continue;
      throw std::runtime_error(fmt::format("poll: {}", std::strerror(errno)));
    }
    for (const auto& p : polls) {
      if (!(p.revents & (POLLIN | POLLHUP | POLLERR))) continue;
      Child& c = running.at(p.fd);
      char buf[65536];
      const ssize_t n = ::read(p.fd, buf, sizeof buf);
      if (n > 0) {
        c.buffer.append(buf, static_cast<std::size_t>(n));
        continue;
      }
      if (n < 0 && errno == EINTR) continue;
      // EOF (or a read error): the child is done.
      ::close(p.fd);
      int status = 0;
      while (::waitpid(c.pid, &status, 0) < 0 && errno == EINTR) {
      }
      const std::size_t index = c.index;
      out[index] = Decode(c, status);
      running.erase(p.fd);  // before on_done: a reaped worker must not be killed again if on_done throws
      if (on_done) on_done(index, out[index]);
    }
  }
  return out;
}

bool ValidExecutorName(const std::string& kind, std::string* error) {
  if (kind == "inprocess" || kind == "fork" || kind == "mpi") return true;
  if (error) *error = fmt::format("executor '{}' unknown; expected fork, inprocess or mpi", kind);
  return false;
}

std::shared_ptr<JobExecutor> MakeExecutor(const std::string& kind, int workers) {
  if (kind == "inprocess") return std::make_shared<InProcessExecutor>();
  if (kind == "fork") return std::make_shared<ForkExecutor>(workers);
#ifdef HW_HAVE_MPI
  if (kind == "mpi") return MpiExecutor::Instance();
#endif
  throw std::invalid_argument(fmt::format("unknown executor '{}': use inprocess, fork{}", kind,
#ifdef HW_HAVE_MPI
                                          ", mpi"
#else
                                          " (this build has no MPI)"
#endif
                                          ));
}

}  // namespace hw::sdp
