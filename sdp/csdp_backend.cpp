#include "sdp/csdp_backend.hpp"
#include "sdp/csdp_operators.hpp"
#include "sdp/csdp_schur.hpp"

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <map>
#include <mutex>
#include <new>

#include <fmt/format.h>

extern "C" {
#include <csdp/declarations.h>
}

// ---------------------------------------------------------------------------------------------------
// How options reach CSDP. easy_sdp() takes no parameters: it calls initparams(), which reads a file
// "param.csdp" from the working directory (or uses built-in defaults with printlevel 1, i.e. a log on
// stdout). A shared file cannot carry per-solve options when solves run concurrently, so this file
// defines initparams() itself; linked before the static libsdp.a (see sdp/CMakeLists.txt), it replaces
// the archive's member (libsdp_la-initparams.o holds nothing else). The options of the solve running on
// the calling thread travel in a thread_local. user_exit(), CSDP's documented per-iteration hook, is
// replaced the same way to count iterations (easy_sdp does not return the count).
//
// Thread safety: libsdp 6.2 as built by Debian is NOT safe to run concurrently. op_o() (the Schur
// complement assembly) keeps a function-static work array ("b work.0" in `nm libsdp.a`), allocated on the
// first iteration and freed at the end of a solve; CSDP makes it thread-private only when built with
// OpenMP, which Debian's build is not. Two concurrent solves read each other's freed memory and free it
// twice (valgrind showed exactly that in the concurrency test). Every easy_sdp() call in the process is
// therefore serialised by CsdpMutex(); setup, result extraction and certificate checks run outside it.
// ---------------------------------------------------------------------------------------------------
namespace {

struct CsdpCallSettings {
  bool active = false;
  paramstruc params{};
  int printlevel = 0;
  int iterations = 0;
};
thread_local CsdpCallSettings tls_csdp;

void CsdpDefaults(paramstruc* p, int* printlevel) {  // CSDP 6.2's built-in defaults
  p->axtol = 1.0e-8;
  p->atytol = 1.0e-8;
  p->objtol = 1.0e-8;
  p->pinftol = 1.0e8;
  p->dinftol = 1.0e8;
  p->maxiter = 100;
  p->minstepfrac = 0.90;
  p->maxstepfrac = 0.97;
  p->minstepp = 1.0e-8;
  p->minstepd = 1.0e-8;
  p->usexzgap = 1;
  p->tweakgap = 0;
  p->affine = 0;
  p->perturbobj = 1;
  p->fastmode = 0;
  *printlevel = 1;
}

}  // namespace

extern "C" void initparams(struct paramstruc* params, int* pprintlevel) {
  CsdpDefaults(params, pprintlevel);
  if (tls_csdp.active) {
    *params = tls_csdp.params;
    *pprintlevel = tls_csdp.printlevel;
  }
}

extern "C" int user_exit(int, int, struct blockmatrix, double*, double, double, double, struct constraintmatrix*,
                         struct blockmatrix, double*, struct blockmatrix, struct paramstruc) {
  ++tls_csdp.iterations;
  return 0;
}

namespace hw::sdp {
namespace {

using Clock = std::chrono::steady_clock;

std::mutex& CsdpMutex() {
  static std::mutex mu;
  return mu;
}

template <typename T>
T* alloc(std::size_t n) {  // CSDP frees with free(): allocate with calloc
  T* p = static_cast<T*>(std::calloc(n, sizeof(T)));
  if (!p) throw std::bad_alloc();
  return p;
}

// Owns everything handed to CSDP and releases it with free_prob() (which frees C, a, the constraint
// lists, X, y and Z), also when an exception unwinds.
struct CsdpData {
  int n = 0, k = 0;
  blockmatrix C{}, X{}, Z{};
  double* a = nullptr;
  double* y = nullptr;
  constraintmatrix* constraints = nullptr;
  bool solution_allocated = false;
  ~CsdpData() {
    if (solution_allocated) {
      free_prob(n, k, C, a, constraints, X, y, Z);
      return;
    }
    // Partial construction: free what exists, in CSDP's layout.
    if (constraints) {
      for (int i = 1; i <= k; ++i)
        for (sparseblock* p = constraints[i].blocks; p;) {
          sparseblock* next = p->next;
          std::free(p->entries);
          std::free(p->iindices);
          std::free(p->jindices);
          std::free(p);
          p = next;
        }
      std::free(constraints);
    }
    if (C.blocks) {
      for (int b = 1; b <= C.nblocks; ++b) std::free(C.blocks[b].data.vec);
      std::free(C.blocks);
    }
    std::free(a);
  }
};

// Expects the canonical problem of SolveCanonical(): no duplicates, no zeros, every F_i non-empty.
SdpSummary SolveWithCsdp(const SdpOptions& options, const LmiProblem& problem) {
  SdpSummary out;
  const auto t0 = Clock::now();
  const int nblocks = static_cast<int>(problem.blocks.size());
  CsdpData d;
  d.k = problem.num_vars();
  for (const auto& b : problem.blocks) d.n += b.size;

  // C = F_0. Block matrices are 1-based; MATRIX blocks are dense column-major (ijtok takes 1-based
  // indices), DIAG blocks are 1-based vectors.
  d.C.nblocks = nblocks;
  d.C.blocks = alloc<blockrec>(nblocks + 1);
  for (int b = 0; b < nblocks; ++b) {
    const int s = problem.blocks[b].size;
    auto& blk = d.C.blocks[b + 1];
    blk.blocksize = s;
    if (problem.blocks[b].kind == BlockSpec::Kind::kDiagonal) {
      blk.blockcategory = DIAG;
      blk.data.vec = alloc<double>(s + 1);
    } else {
      blk.blockcategory = MATRIX;
      blk.data.mat = alloc<double>(static_cast<std::size_t>(s) * s);
    }
  }
  for (const auto& e : problem.F[0]) {
    auto& blk = d.C.blocks[e.block + 1];
    if (blk.blockcategory == DIAG) {
      blk.data.vec[e.row + 1] += e.value;
    } else {
      const int s = blk.blocksize;
      blk.data.mat[ijtok(e.row + 1, e.col + 1, s)] += e.value;
      if (e.row != e.col) blk.data.mat[ijtok(e.col + 1, e.row + 1, s)] += e.value;
    }
  }
  d.a = alloc<double>(d.k + 1);
  for (int i = 0; i < d.k; ++i) d.a[i + 1] = problem.c[i];

  // A_i = F_i: one sparseblock per non-empty block (upper triangle, 1-based), linked in block order.
  d.constraints = alloc<constraintmatrix>(d.k + 1);
  for (int i = 1; i <= d.k; ++i) {
    std::map<int, std::vector<const Entry*>> by_block;
    for (const auto& e : problem.F[i]) by_block[e.block].push_back(&e);
    for (auto it = by_block.rbegin(); it != by_block.rend(); ++it) {
      auto* sb = alloc<sparseblock>(1);
      sb->next = d.constraints[i].blocks;  // linked before its fields so a throw below frees it
      d.constraints[i].blocks = sb;
      const int cnt = static_cast<int>(it->second.size());
      sb->blocknum = it->first + 1;
      sb->blocksize = problem.blocks[it->first].size;
      sb->constraintnum = i;
      sb->numentries = cnt;
      sb->issparse = 1;
      sb->nextbyblock = nullptr;
      sb->entries = alloc<double>(cnt + 1);
      sb->iindices = alloc<int>(cnt + 1);
      sb->jindices = alloc<int>(cnt + 1);
      for (int q = 0; q < cnt; ++q) {
        sb->entries[q + 1] = it->second[q]->value;
        sb->iindices[q + 1] = it->second[q]->row + 1;
        sb->jindices[q + 1] = it->second[q]->col + 1;
      }
    }
  }
  out.setup_seconds = std::chrono::duration<double>(Clock::now() - t0).count();

  double pobj = 0.0, dobj = 0.0;
  int ret;
  double wait_seconds = 0.0;
  {
    const auto t_wait = Clock::now();
    std::lock_guard<std::mutex> lock(CsdpMutex());
    wait_seconds = std::chrono::duration<double>(Clock::now() - t_wait).count();
    const auto t1 = Clock::now();
    tls_csdp.active = true;
    CsdpDefaults(&tls_csdp.params, &tls_csdp.printlevel);
    tls_csdp.params.axtol = options.feasibility_tolerance;   // relative primal infeasibility (our F_i . X = c_i)
    tls_csdp.params.atytol = options.feasibility_tolerance;  // relative dual infeasibility (our LMI)
    tls_csdp.params.objtol = options.gap_tolerance;          // relative gap
    tls_csdp.params.maxiter = options.max_iterations;
    tls_csdp.printlevel = options.verbose ? 1 : 0;
    tls_csdp.iterations = 0;
    initsoln(d.n, d.k, d.C, d.a, d.constraints, &d.X, &d.y, &d.Z);  // easy_sdp starts from (X, y, Z)
    d.solution_allocated = true;
    {
      const CsdpSolveScope scope;  // op_o(), op_a() and op_at() keep this solve's constraint structure
      ret = easy_sdp(d.n, d.k, d.C, d.a, d.constraints, 0.0, &d.X, &d.y, &d.Z, &pobj, &dobj);
    }
    out.iterations = tls_csdp.iterations;
    tls_csdp.active = false;
    out.solve_seconds = std::chrono::duration<double>(Clock::now() - t1).count();
  }

  out.lower_bound = pobj + problem.objective_offset;   // tr(C X) = F_0 . X
  out.primal_value = dobj + problem.objective_offset;  // a^T y = c^T y
  out.relative_gap = RelativeGap(dobj, pobj);
  out.y.assign(d.y + 1, d.y + 1 + d.k);
  for (int b = 1; b <= nblocks; ++b) {
    const int s = d.X.blocks[b].blocksize;
    Eigen::MatrixXd Xb = Eigen::MatrixXd::Zero(s, s), Zb = Eigen::MatrixXd::Zero(s, s);
    if (d.X.blocks[b].blockcategory == DIAG) {
      for (int i = 0; i < s; ++i) {
        Xb(i, i) = d.X.blocks[b].data.vec[i + 1];
        Zb(i, i) = d.Z.blocks[b].data.vec[i + 1];
      }
    } else {
      Xb = Eigen::Map<const Eigen::MatrixXd>(d.X.blocks[b].data.mat, s, s);
      Zb = Eigen::Map<const Eigen::MatrixXd>(d.Z.blocks[b].data.mat, s, s);
    }
    out.X.push_back(std::move(Xb));
    out.Z.push_back(std::move(Zb));
  }
  {  // CSDP's relative residuals: ||A(X) - a|| / (1 + ||a||) and ||A^T y - C - Z||_F / (1 + ||C||_F).
    double* workvec = alloc<double>(d.k + 1);
    blockmatrix work;
    alloc_mat(d.C, &work);
    out.primal_infeasibility = pinfeas(d.k, d.constraints, d.X, d.a, workvec);
    out.dual_infeasibility = dinfeas(d.k, d.C, d.constraints, d.y, d.Z, work);
    free_mat(work);
    std::free(workvec);
  }
  out.details = {{"return_code", ret}, {"pobj", pobj}, {"dobj", dobj}, {"iterations", out.iterations},
                 {"lock_wait_seconds", wait_seconds}, {"schur_assembly", CsdpSchurAssembly()},
                 {"linear_operators", CsdpOperators()}};

  // CSDP 6.2 return codes (CSDP user's guide; its primal is max tr(CX), A(X) = a, X >= 0):
  //   0 solved; 1 primal infeasible = no X = our problem unbounded below (y holds the ray);
  //   2 dual infeasible = no y = our LMI infeasible (X holds the certificate); 3 partial success
  //   (solved to reduced accuracy); 4 iteration limit; 5 stuck at the edge of primal feasibility;
  //   6 stuck at the edge of dual feasibility; 7 lack of progress; 8 X, Z or O singular; 9 NaN/Inf.
  static const char* kMeaning[] = {"solved",
                                   "CSDP primal infeasible (our objective is unbounded below)",
                                   "CSDP dual infeasible (our LMI is infeasible)",
                                   "partial success (reduced accuracy)",
                                   "maximum iterations reached",
                                   "stuck at the edge of primal feasibility",
                                   "stuck at the edge of dual feasibility",
                                   "lack of progress",
                                   "X, Z or O singular",
                                   "NaN or Inf detected"};
  switch (ret) {
    case 0: out.status = SdpStatus::kOptimal; break;
    case 1: out.status = SdpStatus::kUnbounded; break;
    case 2: out.status = SdpStatus::kInfeasible; break;
    case 3: out.status = SdpStatus::kInaccurate; break;
    case 4: out.status = SdpStatus::kIterationLimit; break;
    default: out.status = SdpStatus::kNumericalTrouble; break;
  }
  out.message = fmt::format("CSDP code {} ({}) after {} iterations: tr(F0 X) {:.9g}, c'y {:.9g}", ret,
                            ret >= 0 && ret <= 9 ? kMeaning[ret] : "unknown failure", out.iterations, pobj, dobj);
  if (out.status == SdpStatus::kInfeasible || out.status == SdpStatus::kUnbounded)
    ResolveInfeasibilityClaim(options, problem, &out);
  AcceptNearOptimal(options, &out);
  return out;
}

}  // namespace

SdpSummary CsdpSolver::Solve(const SdpOptions& options, const LmiProblem& problem) {
  return SolveAsBackend(name(), options, problem,
                        [](const SdpOptions& o, const LmiProblem& p) { return SolveWithCsdp(o, p); });
}

}  // namespace hw::sdp
