#include "sdp/dsdp_backend.hpp"

#include <chrono>
#include <cmath>
#include <mutex>
#include <stdexcept>
#include <string>
#include <vector>

#include <fmt/format.h>

#include <dsdp/dsdp5.h>  // declares its functions extern "C" itself

namespace hw::sdp {
namespace {

using Clock = std::chrono::steady_clock;

double SecondsSince(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

// Thread safety: DSDP 5.8 as built by Debian keeps process-wide state. Its f2c-translated triangular solve
// (dtrsm2.o) keeps its locals in static storage (`nm libdsdp.a` shows k.2, i.4, j.5, temp.0, ... in .bss), and
// the event log (DSDPCreate re-initialises `eventlog`), the vector counters (`nvecs`) and the print levels are
// globals. Every DSDP call of a solve, from DSDPCreate to DSDPDestroy, therefore runs under this mutex;
// building the data and reading the results back into Eigen run outside it.
std::mutex& DsdpMutex() {
  static std::mutex mu;
  return mu;
}

// Where each of our blocks lives in DSDP. PSD blocks become blocks of one SDP cone, the rows of diagonal blocks
// become rows of one LP cone. Blocks and LP rows without an entry in any F_i are left out: they only say
// 0 >= 0, and DSDP's barrier needs an interior there (a zero LP row forces its infeasibility variable r > 0).
// Their multiplier is X = 0.
struct DsdpLayout {
  std::vector<int> sdp_block;            // our block -> block of the SDP cone, or -1
  std::vector<std::vector<int>> lp_row;  // our diagonal block, row -> row of the LP cone, or -1
  std::vector<int> sdp_sizes;            // size of each SDP-cone block
  int lp_size = 0;
};

DsdpLayout MakeLayout(const LmiProblem& problem) {
  const int nblocks = static_cast<int>(problem.blocks.size());
  std::vector<char> used(nblocks, 0);
  std::vector<std::vector<char>> row_used(nblocks);
  for (int b = 0; b < nblocks; ++b)
    if (problem.blocks[b].kind == BlockSpec::Kind::kDiagonal) row_used[b].assign(problem.blocks[b].size, 0);
  for (const auto& F : problem.F)
    for (const auto& e : F) {
      used[e.block] = 1;
      if (!row_used[e.block].empty()) row_used[e.block][e.row] = 1;
    }
  DsdpLayout layout;
  layout.sdp_block.assign(nblocks, -1);
  layout.lp_row.resize(nblocks);
  for (int b = 0; b < nblocks; ++b) {
    if (problem.blocks[b].kind == BlockSpec::Kind::kPsd) {
      if (!used[b]) continue;
      layout.sdp_block[b] = static_cast<int>(layout.sdp_sizes.size());
      layout.sdp_sizes.push_back(problem.blocks[b].size);
    } else {
      layout.lp_row[b].assign(problem.blocks[b].size, -1);
      for (int r = 0; r < problem.blocks[b].size; ++r)
        if (row_used[b][r]) layout.lp_row[b][r] = layout.lp_size++;
    }
  }
  return layout;
}

// Packed symmetric storage of DSDP ('P'): element (i, j) with i >= j of an n x n block sits at i (i + 1) / 2 + j
// (the lower triangle row by row). Our entries are upper-triangular (row <= col), i.e. (col, row) there.
int PackedIndex(int row, int col) { return col * (col + 1) / 2 + row; }

// The slack F(y) = sum y_i F_i - F_0, block by block.
std::vector<Eigen::MatrixXd> SlackAt(const LmiProblem& problem, const std::vector<double>& y) {
  std::vector<Eigen::MatrixXd> Z;
  for (const auto& b : problem.blocks) Z.push_back(Eigen::MatrixXd::Zero(b.size, b.size));
  for (int i = 0; i <= problem.num_vars(); ++i) {
    const double w = i == 0 ? -1.0 : y[i - 1];
    for (const auto& e : problem.F[i]) {
      Z[e.block](e.row, e.col) += w * e.value;
      if (e.row != e.col) Z[e.block](e.col, e.row) += w * e.value;
    }
  }
  return Z;
}

// Smallest and largest-magnitude eigenvalue over all blocks of a slack (diagonal blocks: their diagonal).
struct SlackSpectrum {
  double min = INFINITY;
  double max_abs = 0.0;
};

SlackSpectrum SpectrumOf(const LmiProblem& problem, const std::vector<Eigen::MatrixXd>& Z) {
  SlackSpectrum s;
  for (std::size_t b = 0; b < Z.size(); ++b) {
    const Eigen::VectorXd lambda =
        problem.blocks[b].kind == BlockSpec::Kind::kDiagonal
            ? Eigen::VectorXd(Z[b].diagonal())
            : Eigen::VectorXd(Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(Z[b], Eigen::EigenvaluesOnly).eigenvalues());
    s.min = std::min(s.min, lambda.minCoeff());
    s.max_abs = std::max(s.max_abs, lambda.cwiseAbs().maxCoeff());
  }
  return s;
}

// DSDP starts from y0 = initial_y only as far as its infeasibility variable r lets it (its slack is
// C - A^T y + r I). Left to itself it raises r0 by factors of 100 until that is positive definite and then scales
// it up by the dimension, which washes the start out: the iterates equal a cold start's to 1e-12. With a warm
// start r0 is set here: enough to make F(y0) + r0 I positive definite, plus a margin of 1 + max |lambda(F(y0))|
// that keeps the start off the boundary (a start on the boundary, margin ~0, saved no iterations; with this
// margin a start at the optimum does: tests/dsdp_backend_test.cpp, WarmStartIsUsed).
double WarmStartShift(const LmiProblem& problem, const std::vector<double>& y0) {
  const SlackSpectrum s = SpectrumOf(problem, SlackAt(problem, y0));
  return std::max(0.0, -s.min) + 1.0 + s.max_abs;
}

// The data as DSDP takes it. DSDP keeps pointers into these arrays until DSDPDestroy(), so they outlive the solve.
struct DsdpData {
  struct SparseMatrix {
    int block = 0;     // SDP-cone block
    int variable = 0;  // 0 = C, i = A_i
    std::vector<int> index;
    std::vector<double> value;
  };
  std::vector<SparseMatrix> sdp;
  std::vector<int> sdp_matrices_per_block;  // sparsity hint: number of nonzero matrices per block
  // LP cone, column-compressed by variable: the entries of variable i (0 = C) are [lp_begin[i], lp_begin[i + 1]).
  std::vector<int> lp_begin;
  std::vector<int> lp_row;
  std::vector<double> lp_value;
};

// C = -F_0 and A_i = -F_i: DSDP's slack C - sum A_i y_i is then our F(y).
DsdpData BuildData(const LmiProblem& problem, const DsdpLayout& layout) {
  DsdpData d;
  d.sdp_matrices_per_block.assign(layout.sdp_sizes.size(), 0);
  d.lp_begin.push_back(0);
  for (int i = 0; i <= problem.num_vars(); ++i) {
    for (const auto& e : problem.F[i]) {
      const int sb = layout.sdp_block[e.block];
      if (sb >= 0) {
        if (d.sdp.empty() || d.sdp.back().block != sb || d.sdp.back().variable != i) {
          d.sdp.push_back({sb, i, {}, {}});
          ++d.sdp_matrices_per_block[sb];
        }
        d.sdp.back().index.push_back(PackedIndex(e.row, e.col));
        d.sdp.back().value.push_back(-e.value);
      } else if (problem.blocks[e.block].kind == BlockSpec::Kind::kDiagonal) {
        d.lp_row.push_back(layout.lp_row[e.block][e.row]);
        d.lp_value.push_back(-e.value);
      }
    }
    d.lp_begin.push_back(static_cast<int>(d.lp_row.size()));
  }
  return d;
}

// A DSDP call that returned an error code (DSDP prints its own traceback only for such errors).
struct DsdpCallFailed : std::runtime_error {
  DsdpCallFailed(const char* call, int code)
      : std::runtime_error(fmt::format("DSDP call {} failed with code {}", call, code)) {}
};

void Check(int info, const char* call) {
  if (info != 0) throw DsdpCallFailed(call, info);
}

// Owns the solver object (and the cones it holds).
class DsdpHandle {
 public:
  explicit DsdpHandle(int m) { Check(DSDPCreate(m, &dsdp_), "DSDPCreate"); }
  ~DsdpHandle() { DSDPDestroy(dsdp_); }
  DsdpHandle(const DsdpHandle&) = delete;
  DsdpHandle& operator=(const DsdpHandle&) = delete;
  DSDP get() const { return dsdp_; }

 private:
  DSDP dsdp_ = nullptr;
};

struct DsdpCones {
  SDPCone sdp = nullptr;
  LPCone lp = nullptr;
};

DsdpCones LoadCones(DSDP dsdp, const DsdpLayout& layout, const DsdpData& d) {
  DsdpCones cones;
  const int nsdp = static_cast<int>(layout.sdp_sizes.size());
  if (nsdp > 0) {
    Check(DSDPCreateSDPCone(dsdp, nsdp, &cones.sdp), "DSDPCreateSDPCone");
    for (int j = 0; j < nsdp; ++j) {
      Check(SDPConeSetBlockSize(cones.sdp, j, layout.sdp_sizes[j]), "SDPConeSetBlockSize");
      Check(SDPConeSetStorageFormat(cones.sdp, j, 'P'), "SDPConeSetStorageFormat");
      Check(SDPConeSetSparsity(cones.sdp, j, d.sdp_matrices_per_block[j]), "SDPConeSetSparsity");
    }
    // "Add" (not "Set") sums matrices given twice for one (block, variable) instead of replacing them.
    for (const auto& M : d.sdp)
      Check(SDPConeAddASparseVecMat(cones.sdp, M.block, M.variable, layout.sdp_sizes[M.block], 1.0, 0, M.index.data(),
                                    M.value.data(), static_cast<int>(M.index.size())),
            "SDPConeAddASparseVecMat");
  }
  if (layout.lp_size > 0) {
    Check(DSDPCreateLPCone(dsdp, &cones.lp), "DSDPCreateLPCone");
    Check(LPConeSetData(cones.lp, layout.lp_size, d.lp_begin.data(), d.lp_row.data(), d.lp_value.data()),
          "LPConeSetData");
  }
  return cones;
}

// r0 < 0: DSDP chooses its initial infeasibility (no warm start).
void SetOptions(DSDP dsdp, const SdpOptions& options, const LmiProblem& problem, double r0) {
  for (int i = 0; i < problem.num_vars(); ++i)
    Check(DSDPSetDualObjective(dsdp, i + 1, -problem.c[i]), "DSDPSetDualObjective");  // b = -c
  // DSDP stops when (pp - dd) / (1 + |pp|/2 + |dd|/2) <= gap tolerance and its infeasibility variable r (the
  // shift in C - A^T y + r I >= 0) is below the R tolerance: our gap and dual feasibility tolerances.
  Check(DSDPSetGapTolerance(dsdp, options.gap_tolerance), "DSDPSetGapTolerance");
  Check(DSDPSetRTolerance(dsdp, options.feasibility_tolerance), "DSDPSetRTolerance");
  Check(DSDPSetMaxIts(dsdp, options.max_iterations), "DSDPSetMaxIts");
  for (std::size_t i = 0; i < options.initial_y.size(); ++i)
    Check(DSDPSetY0(dsdp, static_cast<int>(i) + 1, options.initial_y[i]), "DSDPSetY0");
  if (r0 >= 0) Check(DSDPSetR0(dsdp, r0), "DSDPSetR0");
  if (options.verbose) Check(DSDPSetStandardMonitor(dsdp, 1), "DSDPSetStandardMonitor");
}

const char* ReasonName(DSDPTerminationReason r) {
  switch (r) {
    case DSDP_CONVERGED: return "converged";
    case DSDP_INFEASIBLE_START: return "infeasible start";
    case DSDP_SMALL_STEPS: return "small steps";
    case DSDP_INDEFINITE_SCHUR_MATRIX: return "indefinite Schur matrix";
    case DSDP_MAX_IT: return "maximum iterations";
    case DSDP_NUMERICAL_ERROR: return "numerical error";
    case DSDP_UPPERBOUND: return "dual objective above its bound";
    case DSDP_USER_TERMINATION: return "user termination";
    case CONTINUE_ITERATING: return "still iterating";
  }
  return "unknown";
}

const char* SolutionTypeName(DSDPSolutionType t) {
  switch (t) {
    case DSDP_PDFEASIBLE: return "PDFEASIBLE";
    case DSDP_UNBOUNDED: return "UNBOUNDED";   // (D) unbounded: our objective is unbounded below
    case DSDP_INFEASIBLE: return "INFEASIBLE";  // (D) infeasible: our LMI is infeasible
    case DSDP_PDUNKNOWN: return "PDUNKNOWN";
  }
  return "unknown";
}

// Everything read back from DSDP while the lock is held.
struct DsdpOutcome {
  DSDPTerminationReason reason = CONTINUE_ITERATING;
  DSDPSolutionType type = DSDP_PDUNKNOWN;
  bool x_computed = false;
  std::vector<double> y;
  std::vector<std::vector<double>> sdp_x;  // packed, per SDP-cone block
  std::vector<double> lp_x;
  int iterations = 0;
  double pobj = 0, dobj = 0, ppobj = 0, ddobj = 0, r = 0, trace_x = 0, penalty = 0, mu = 0, y_max = 0;
  double y_lower = 0, y_upper = 0;
  double errors[6] = {0, 0, 0, 0, 0, 0};
  double setup_call_seconds = 0;  // DSDPSetup (Schur structure, data norms, scaling)
  int solve_code = 0;             // DSDPSolve's return code (nonzero: it failed, DSDP printed a traceback)
  int x_code = 0;                 // DSDPComputeX's
};

DsdpOutcome RunDsdp(const SdpOptions& options, const LmiProblem& problem, const DsdpLayout& layout,
                    const DsdpData& data, double r0) {
  DsdpOutcome o;
  const int m = problem.num_vars();
  DsdpHandle handle(m);
  DSDP dsdp = handle.get();
  const DsdpCones cones = LoadCones(dsdp, layout, data);
  SetOptions(dsdp, options, problem, r0);
  const auto t_setup = Clock::now();
  Check(DSDPSetup(dsdp), "DSDPSetup");
  o.setup_call_seconds = SecondsSince(t_setup);
  // A failed DSDPSolve leaves a partial iterate: it is read like any solve that stopped short.
  o.solve_code = DSDPSolve(dsdp);
  Check(DSDPStopReason(dsdp, &o.reason), "DSDPStopReason");
  if (o.reason != DSDP_INFEASIBLE_START) {  // DSDP's own driver skips X after an infeasible start, too
    o.x_code = DSDPComputeX(dsdp);          // may downgrade the reason (X not accurate enough)
    o.x_computed = o.x_code == 0;
  }
  Check(DSDPStopReason(dsdp, &o.reason), "DSDPStopReason");
  if ((o.solve_code != 0 || o.x_code != 0) && o.reason == DSDP_CONVERGED) o.reason = DSDP_NUMERICAL_ERROR;
  Check(DSDPGetSolutionType(dsdp, &o.type), "DSDPGetSolutionType");
  o.y.assign(m, 0.0);
  Check(DSDPGetY(dsdp, o.y.data(), m), "DSDPGetY");
  Check(DSDPGetIts(dsdp, &o.iterations), "DSDPGetIts");
  Check(DSDPGetPObjective(dsdp, &o.pobj), "DSDPGetPObjective");
  Check(DSDPGetDObjective(dsdp, &o.dobj), "DSDPGetDObjective");
  Check(DSDPGetPPObjective(dsdp, &o.ppobj), "DSDPGetPPObjective");
  Check(DSDPGetDDObjective(dsdp, &o.ddobj), "DSDPGetDDObjective");
  Check(DSDPGetR(dsdp, &o.r), "DSDPGetR");
  Check(DSDPGetTraceX(dsdp, &o.trace_x), "DSDPGetTraceX");
  Check(DSDPGetPenaltyParameter(dsdp, &o.penalty), "DSDPGetPenaltyParameter");
  Check(DSDPGetBarrierParameter(dsdp, &o.mu), "DSDPGetBarrierParameter");
  Check(DSDPGetYMaxNorm(dsdp, &o.y_max), "DSDPGetYMaxNorm");
  Check(DSDPGetYBounds(dsdp, &o.y_lower, &o.y_upper), "DSDPGetYBounds");
  Check(DSDPGetFinalErrors(dsdp, o.errors), "DSDPGetFinalErrors");
  if (o.x_computed) {
    for (int j = 0; j < static_cast<int>(layout.sdp_sizes.size()); ++j) {
      double* x = nullptr;
      int nn = 0;
      Check(SDPConeGetXArray(cones.sdp, j, &x, &nn), "SDPConeGetXArray");
      o.sdp_x.emplace_back(x, x + nn);
      Check(SDPConeRestoreXArray(cones.sdp, j, &x, &nn), "SDPConeRestoreXArray");
    }
    if (cones.lp) {
      double* x = nullptr;
      int n = 0;
      Check(LPConeGetXArray(cones.lp, &x, &n), "LPConeGetXArray");
      o.lp_x.assign(x, x + n);
    }
  }
  return o;
}

// X block by block in our layout (left-out blocks and rows, and everything when X was not computed, are 0).
std::vector<Eigen::MatrixXd> MultiplierBlocks(const LmiProblem& problem, const DsdpLayout& layout,
                                              const DsdpOutcome& o) {
  std::vector<Eigen::MatrixXd> X;
  for (std::size_t b = 0; b < problem.blocks.size(); ++b) {
    const int n = problem.blocks[b].size;
    Eigen::MatrixXd Xb = Eigen::MatrixXd::Zero(n, n);
    const int sb = layout.sdp_block[b];
    if (sb >= 0 && sb < static_cast<int>(o.sdp_x.size())) {
      const auto& packed = o.sdp_x[sb];
      for (int i = 0; i < n; ++i)
        for (int j = 0; j <= i; ++j) Xb(i, j) = Xb(j, i) = packed[PackedIndex(j, i)];
    } else if (!layout.lp_row[b].empty() && !o.lp_x.empty()) {
      for (int r = 0; r < n; ++r)
        if (layout.lp_row[b][r] >= 0) Xb(r, r) = o.lp_x[layout.lp_row[b][r]];
    }
    X.push_back(std::move(Xb));
  }
  return X;
}

// ||F||_F of one (upper-triangular) matrix of the problem.
double FrobeniusNorm(const std::vector<Entry>& F) {
  double s = 0.0;
  for (const auto& e : F) s += e.value * e.value * (e.row == e.col ? 1.0 : 2.0);
  return std::sqrt(s);
}

// ||(F_i . X - c_i)_i||_2 / (1 + ||c||_2), as CSDP measures it.
double PrimalInfeasibility(const LmiProblem& problem, const std::vector<Eigen::MatrixXd>& X) {
  double res = 0.0, cnorm = 0.0;
  for (int i = 1; i <= problem.num_vars(); ++i) {
    const double d = InnerProduct(problem.F[i], X) - problem.c[i - 1];
    res += d * d;
    cnorm += problem.c[i - 1] * problem.c[i - 1];
  }
  return std::sqrt(res) / (1.0 + std::sqrt(cnorm));
}

nlohmann::json Details(const DsdpOutcome& o, double wait_seconds) {
  return {{"stop_reason", ReasonName(o.reason)},
          {"stop_reason_code", static_cast<int>(o.reason)},
          {"solution_type", SolutionTypeName(o.type)},
          {"x_computed", o.x_computed},
          {"pobj", o.pobj},
          {"dobj", o.dobj},
          {"ppobj", o.ppobj},
          {"ddobj", o.ddobj},
          {"r", o.r},
          {"trace_x", o.trace_x},
          {"penalty_parameter", o.penalty},
          {"barrier_parameter", o.mu},
          {"y_max", o.y_max},
          {"y_bounds", {o.y_lower, o.y_upper}},
          {"final_errors", std::vector<double>(o.errors, o.errors + 6)},
          {"iterations", o.iterations},
          {"solve_code", o.solve_code},
          {"compute_x_code", o.x_code},
          {"dsdp_setup_seconds", o.setup_call_seconds},
          {"lock_wait_seconds", wait_seconds}};
}

// DSDP's gap measure, (p - d) / (1 + |p|/2 + |d|/2), on the returned y and X.
double DsdpRelativeGap(double primal, double dual) {
  return std::abs(primal - dual) / (1.0 + 0.5 * std::abs(primal) + 0.5 * std::abs(dual));
}

// DSDP's outcome -> our status (before the certificate checks):
//   converged (or dual objective above its bound) + PDFEASIBLE, with the returned y and X within the gap and
//   feasibility tolerances                              -> kOptimal; otherwise (incl. PDUNKNOWN) kInaccurate
//   maximum iterations                                  -> kIterationLimit
//   small steps, numerical error (DSDP: "check solution") -> kInaccurate (AcceptNearOptimal may promote it)
//   indefinite Schur matrix, infeasible start, other    -> kNumericalTrouble
// DSDP's claims UNBOUNDED / INFEASIBLE are handled by the caller with the certificates.
SdpStatus StatusFromReason(const SdpOptions& options, const DsdpOutcome& o, const SdpSummary& s, double dsdp_gap) {
  switch (o.reason) {
    case DSDP_CONVERGED:
    case DSDP_UPPERBOUND: {
      const bool within = dsdp_gap <= options.gap_tolerance &&
                          s.primal_infeasibility <= options.feasibility_tolerance &&
                          s.dual_infeasibility <= options.feasibility_tolerance;
      return o.type == DSDP_PDFEASIBLE && within ? SdpStatus::kOptimal : SdpStatus::kInaccurate;
    }
    case DSDP_MAX_IT: return SdpStatus::kIterationLimit;
    case DSDP_SMALL_STEPS:
    case DSDP_NUMERICAL_ERROR: return SdpStatus::kInaccurate;
    default: return SdpStatus::kNumericalTrouble;
  }
}

// Applies DSDP's infeasible/unbounded label through the certificates. After a converged solve the label decides
// like CSDP's and SDPA's (checked certificate, else kNumericalTrouble); after a solve that stopped short a
// checked certificate still settles the problem, and an unchecked one leaves the stopped-short status.
void ApplySolutionType(const SdpOptions& options, const LmiProblem& problem, const DsdpOutcome& o, SdpSummary* s) {
  if (o.type != DSDP_INFEASIBLE && o.type != DSDP_UNBOUNDED) return;
  const bool converged = o.reason == DSDP_CONVERGED || o.reason == DSDP_UPPERBOUND;
  SdpSummary claim = *s;
  claim.status = o.type == DSDP_INFEASIBLE ? SdpStatus::kInfeasible : SdpStatus::kUnbounded;
  ResolveInfeasibilityClaim(options, problem, &claim);
  if (converged || claim.status != SdpStatus::kNumericalTrouble) *s = std::move(claim);
}

// Expects the canonical problem of SolveCanonical(): no duplicates, no zeros, every F_i non-empty.
SdpSummary SolveWithDsdp(const SdpOptions& options, const LmiProblem& problem) {
  SdpSummary out;
  const auto t0 = Clock::now();
  const DsdpLayout layout = MakeLayout(problem);
  const DsdpData data = BuildData(problem, layout);
  const double r0 = options.initial_y.empty() ? -1.0 : WarmStartShift(problem, options.initial_y);
  out.setup_seconds = SecondsSince(t0);
  DsdpOutcome o;
  double wait_seconds = 0.0;
  try {
    const auto t_wait = Clock::now();
    std::lock_guard<std::mutex> lock(DsdpMutex());
    wait_seconds = SecondsSince(t_wait);
    const auto t1 = Clock::now();
    o = RunDsdp(options, problem, layout, data, r0);
    out.solve_seconds = SecondsSince(t1);
  } catch (const DsdpCallFailed& e) {
    out.status = SdpStatus::kNumericalTrouble;
    out.message = e.what();
    out.details = {{"lock_wait_seconds", wait_seconds}};
    return out;
  }
  out.iterations = o.iterations;
  out.y = o.y;
  out.X = MultiplierBlocks(problem, layout, o);
  out.Z = SlackAt(problem, out.y);
  double cy = 0.0;
  for (int i = 0; i < problem.num_vars(); ++i) cy += problem.c[i] * out.y[i];
  const double f0x = InnerProduct(problem.F[0], out.X);  // = -C . X, DSDP's -pobj
  out.primal_value = cy + problem.objective_offset;
  out.lower_bound = f0x + problem.objective_offset;
  out.relative_gap = RelativeGap(cy, f0x);
  out.primal_infeasibility = PrimalInfeasibility(problem, out.X);
  // Of the LMI at the returned y: max(0, -lambda_min(F(y))) / (1 + ||F_0||_F). (DSDP's own measure, its r, belongs
  // to its last iterate, which may be newer than the y it returns.)
  out.dual_infeasibility = std::max(0.0, -SpectrumOf(problem, out.Z).min) / (1.0 + FrobeniusNorm(problem.F[0]));
  out.details = Details(o, wait_seconds);
  if (r0 >= 0) out.details["warm_start_r0"] = r0;
  const double dsdp_gap = DsdpRelativeGap(cy, f0x);
  out.details["dsdp_relative_gap"] = dsdp_gap;
  out.message = fmt::format("DSDP {} ({}) after {} iterations: F0.X {:.9g}, c'y {:.9g}", ReasonName(o.reason),
                            SolutionTypeName(o.type), o.iterations, f0x, cy);
  out.status = StatusFromReason(options, o, out, dsdp_gap);
  ApplySolutionType(options, problem, o, &out);
  AcceptNearOptimal(options, &out);
  return out;
}

}  // namespace

SdpSummary DsdpSolver::Solve(const SdpOptions& options, const LmiProblem& problem) {
  return SolveAsBackend(name(), options, problem,
                        [](const SdpOptions& o, const LmiProblem& p) { return SolveWithDsdp(o, p); });
}

}  // namespace hw::sdp
