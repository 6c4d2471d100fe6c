#include "sdp/sdpa_backend.hpp"

#include <chrono>
#include <cmath>
#include <iostream>
#include <sstream>
#include <limits>
#include <mutex>

#include <fmt/format.h>
#include <sdpa_call.h>

namespace hw::sdp {
namespace {

using Clock = std::chrono::steady_clock;

// Thread safety: SDPA 7.3.16 is NOT safe to run concurrently. Its Schur-complement assembly hands
// columns to worker threads through static class members (sdpa::Newton::Column_Number, job_mutex,
// job_cond, mutex_flag, Calc_F1: `nm libsdpa.a` shows them in .bss), shared by every SDPA object, and
// the timing code keeps function-local statics. All SDPA solves in the process are therefore
// serialised by this mutex; run concurrent jobs with CSDP when throughput matters.
std::mutex& SdpaMutex() {
  static std::mutex mu;
  return mu;
}

// SDPA writes warnings ("pdINF criteria", "Strange behavior : primal < dual", "maxIteration is reached")
// to std::cout through its rMessage macro, whatever setDisplay() says. While a quiet solve runs (solves
// are serialised, so one at a time) std::cout's buffer is swapped for a string that ends up in
// details["messages"]. Consequence: other threads must not write to std::cout during SDPA solves
// (hwbounds prints with fmt/printf to stdout or to stderr, which this does not touch).
class CoutCapture {
 public:
  explicit CoutCapture(bool active) : active_(active) {
    if (active_) saved_ = std::cout.rdbuf(buffer_.rdbuf());
  }
  ~CoutCapture() {
    if (active_) std::cout.rdbuf(saved_);
  }
  std::string text() const { return buffer_.str(); }

 private:
  bool active_;
  std::ostringstream buffer_;
  std::streambuf* saved_ = nullptr;
};

// Expects the canonical problem of SolveCanonical(): no duplicates, no zeros, every F_i non-empty.
SdpSummary SolveWithSdpa(const SdpOptions& options, const LmiProblem& problem, SDPA::ParameterType parameters) {
  SdpSummary out;
  const auto t_wait = Clock::now();
  std::lock_guard<std::mutex> lock(SdpaMutex());
  const double wait_seconds = std::chrono::duration<double>(Clock::now() - t_wait).count();
  CoutCapture capture(!options.verbose);
  const auto t0 = Clock::now();
  const int m = problem.num_vars();
  const int nblocks = static_cast<int>(problem.blocks.size());
  SDPA sdpa;
  // SDPA's default parameter set, with our tolerances and iteration limit on top.
  sdpa.setParameterType(parameters);
  sdpa.setParameterMaxIteration(options.max_iterations);
  sdpa.setParameterEpsilonStar(options.gap_tolerance);
  sdpa.setParameterEpsilonDash(options.feasibility_tolerance);
  sdpa.setDisplay(options.verbose ? stdout : nullptr);
  sdpa.setResultFile(nullptr);
  sdpa.setNumThreads(1);
  sdpa.inputConstraintNumber(m);
  sdpa.inputBlockNumber(nblocks);
  for (int b = 0; b < nblocks; ++b) {
    const bool lp = problem.blocks[b].kind == BlockSpec::Kind::kDiagonal;
    sdpa.inputBlockSize(b + 1, lp ? -problem.blocks[b].size : problem.blocks[b].size);
    sdpa.inputBlockType(b + 1, lp ? SDPA::LP : SDPA::SDP);
  }
  sdpa.initializeUpperTriangleSpace();
  for (int i = 0; i < m; ++i) sdpa.inputCVec(i + 1, problem.c[i]);
  for (int i = 0; i <= m; ++i)
    for (const auto& e : problem.F[i]) sdpa.inputElement(i, e.block + 1, e.row + 1, e.col + 1, e.value);
  sdpa.initializeUpperTriangle();
  sdpa.initializeSolve();
  out.setup_seconds = std::chrono::duration<double>(Clock::now() - t0).count();
  const auto t1 = Clock::now();
  sdpa.solve();
  out.solve_seconds = std::chrono::duration<double>(Clock::now() - t1).count();

  // SDPA's primal: min c'x, X = sum F_i x_i - F_0 >= 0 (ours, x = y); its dual: max F_0 . Y,
  // F_i . Y = c_i, Y >= 0 (Y = our multiplier X).
  out.iterations = sdpa.getIteration();
  out.primal_value = sdpa.getPrimalObj() + problem.objective_offset;
  out.lower_bound = sdpa.getDualObj() + problem.objective_offset;
  out.primal_infeasibility = sdpa.getDualError();  // of F_i . Y = c_i
  out.dual_infeasibility = sdpa.getPrimalError();  // of the LMI at x
  out.relative_gap = RelativeGap(sdpa.getPrimalObj(), sdpa.getDualObj());
  const double* x = sdpa.getResultXVec();
  out.y.assign(x, x + m);
  for (int b = 0; b < nblocks; ++b) {
    const int n = problem.blocks[b].size;
    Eigen::MatrixXd Y = Eigen::MatrixXd::Zero(n, n), S = Eigen::MatrixXd::Zero(n, n);
    const double* yb = sdpa.getResultYMat(b + 1);
    const double* sb = sdpa.getResultXMat(b + 1);
    if (problem.blocks[b].kind == BlockSpec::Kind::kDiagonal) {  // LP blocks come back as vectors
      for (int i = 0; i < n; ++i) {
        Y(i, i) = yb[i];
        S(i, i) = sb[i];
      }
    } else {
      Y = Eigen::Map<const Eigen::MatrixXd>(yb, n, n);
      S = Eigen::Map<const Eigen::MatrixXd>(sb, n, n);
    }
    out.X.push_back(std::move(Y));
    out.Z.push_back(std::move(S));
  }
  char phase[64] = {0};
  sdpa.getPhaseString(phase);
  const SDPA::PhaseType phase_value = sdpa.getPhaseValue();
  out.details = {{"phase", phase},
                 {"parameter_set", parameters == SDPA::PARAMETER_STABLE_BUT_SLOW ? "stable_but_slow"
                                   : parameters == SDPA::PARAMETER_DEFAULT       ? "default"
                                                                                 : "unstable_but_fast"},
                 {"primal_obj", sdpa.getPrimalObj()},
                 {"dual_obj", sdpa.getDualObj()},
                 {"primal_error", sdpa.getPrimalError()},
                 {"dual_error", sdpa.getDualError()},
                 {"digits", sdpa.getDigits()},
                 {"mu", sdpa.getMu()},
                 {"iterations", out.iterations},
                 {"lock_wait_seconds", wait_seconds}};
  out.message = fmt::format("SDPA phase {} after {} iterations: c'x {:.9g}, F0.Y {:.9g}", phase, out.iterations,
                            sdpa.getPrimalObj(), sdpa.getDualObj());
  sdpa.terminate();
  if (!capture.text().empty()) out.details["messages"] = capture.text();

  // SDPA phases name SDPA's primal (= our LMI problem) first:
  //   pdOPT       both feasible, gap met                           -> kOptimal
  //   pINF_dFEAS  primal (our LMI) infeasible                      -> kInfeasible (if Y certifies it)
  //   dUNBD       dual unbounded, i.e. our LMI infeasible          -> kInfeasible (if Y certifies it)
  //   pFEAS_dINF  dual infeasible, i.e. our objective unbounded    -> kUnbounded
  //   pUNBD       primal unbounded                                 -> kUnbounded
  //   pdINF       both infeasible                                  -> by the certificates (see below)
  //   pdFEAS, pFEAS, dFEAS, noINFO: stopped early                  -> kIterationLimit at the limit, else kInaccurate
  // No infeasibility/unboundedness label is trusted alone (SDPA said pdINF on a plainly unbounded test
  // problem): ResolveInfeasibilityClaim() decides by the certificates Y (infeasibility) and x (ray).
  switch (phase_value) {
    case SDPA::pdOPT: out.status = SdpStatus::kOptimal; break;
    case SDPA::pINF_dFEAS:
    case SDPA::dUNBD:
    case SDPA::pdINF: out.status = SdpStatus::kInfeasible; break;
    case SDPA::pFEAS_dINF:
    case SDPA::pUNBD: out.status = SdpStatus::kUnbounded; break;
    default:
      out.status = out.iterations >= options.max_iterations ? SdpStatus::kIterationLimit : SdpStatus::kInaccurate;
      break;
  }
  if (out.status == SdpStatus::kInfeasible || out.status == SdpStatus::kUnbounded)
    ResolveInfeasibilityClaim(options, problem, &out);
  AcceptNearOptimal(options, &out);
  return out;
}

}  // namespace

SdpSummary SdpaSolver::Solve(const SdpOptions& options, const LmiProblem& problem) {
  // SDPA's outcome on degenerate relaxations depends on its parameter set and on the BLAS kernels of the CPU
  // (the same problem stopped at pdFEAS 4e-6 short of the gap on one machine and was optimal on another). A
  // solve that ends neither optimal nor with a certified infeasible/unbounded outcome is repeated with SDPA's
  // default parameter set; the first decided outcome wins, otherwise the first attempt is returned.
  return SolveAsBackend(name(), options, problem, [](const SdpOptions& o, const LmiProblem& p) {
    SdpSummary first = SolveWithSdpa(o, p, SDPA::PARAMETER_STABLE_BUT_SLOW);
    if (first.decided() || !o.retry_with_default_parameters) return first;
    SdpSummary second = SolveWithSdpa(o, p, SDPA::PARAMETER_DEFAULT);
    second.setup_seconds += first.setup_seconds + first.solve_seconds;  // the time of both attempts counts
    second.iterations += first.iterations;
    if (second.decided()) {
      second.message += " [after " + first.message + "]";
      return second;
    }
    first.setup_seconds = second.setup_seconds;
    first.details["iterations_all_attempts"] = second.iterations;  // `iterations` stays the returned attempt's
    first.message += " [default parameters: " + second.message + "]";
    return first;
  });
}

}  // namespace hw::sdp
