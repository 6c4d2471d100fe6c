#include "sdp/csdp_operators.hpp"

#include <vector>

extern "C" {
#include <csdp/declarations.h>
}

#include "sdp/csdp_schur.hpp"

// CSDP's op_a() and op_at() walk each constraint's linked list of sparse blocks and recompute every entry's
// position in every call; on the moment relaxations (tens of thousands of entries, a few calls per iteration)
// that was about 40 % of a solve (perf, benchmarks/setmembership_sdp_bench). Here the constraints are copied once
// per solve into one flat array with the positions precomputed, and the sums run in CSDP's order (constraint by
// constraint, blocks and entries as listed), so the results are the same numbers. Linked before the static
// libsdp.a (sdp/CMakeLists.txt), these definitions replace the archive's, as op_o() in csdp_schur.cpp does.
namespace hw::sdp {
namespace {

struct FlatEntry {
  int index;      // 1-based row index (the position in a diagonal block)
  long p, q;      // positions of (i, j) and (j, i) in a matrix block's column-major data
  double value;
};

// One constraint's entries in one block.
struct Segment {
  int block;
  int begin, end;  // into FlatOperators::entries
};

// Kept for the solve of the thread inside a CsdpSolveScope (one at a time: easy_sdp() runs under CsdpMutex);
// the scope's ends drop it, so a later solve never reads an earlier one's copy.
struct FlatOperators {
  struct constraintmatrix* constraints = nullptr;
  int k = 0;
  std::vector<int> first_segment;  // k + 2 offsets into segments, 1-based like CSDP's constraints
  std::vector<Segment> segments;
  std::vector<FlatEntry> entries;
};

FlatOperators& Cached() {
  static FlatOperators flat;
  return flat;
}
thread_local bool tls_in_solve_scope = false;

void Flatten(int k, struct constraintmatrix* constraints, FlatOperators& f) {
  f = {};
  f.constraints = constraints;
  f.k = k;
  f.first_segment.assign(k + 2, 0);
  for (int i = 1; i <= k; ++i) {
    f.first_segment[i] = static_cast<int>(f.segments.size());
    for (struct sparseblock* ptr = constraints[i].blocks; ptr != nullptr; ptr = ptr->next) {
      Segment s{ptr->blocknum, static_cast<int>(f.entries.size()), 0};
      for (int j = 1; j <= ptr->numentries; ++j) {
        const int ii = ptr->iindices[j], jj = ptr->jindices[j];
        f.entries.push_back({ii, static_cast<long>(ijtok(ii, jj, static_cast<long>(ptr->blocksize))),
                             static_cast<long>(ijtok(jj, ii, static_cast<long>(ptr->blocksize))), ptr->entries[j]});
      }
      s.end = static_cast<int>(f.entries.size());
      f.segments.push_back(s);
    }
  }
  f.first_segment[k + 1] = static_cast<int>(f.segments.size());
}

// The solve's cached copy inside a CsdpSolveScope, else `local` filled for this call.
const FlatOperators& FlatOf(int k, struct constraintmatrix* constraints, FlatOperators& local) {
  if (!tls_in_solve_scope) {
    Flatten(k, constraints, local);
    return local;
  }
  FlatOperators& f = Cached();
  if (f.constraints != constraints || f.k != k) Flatten(k, constraints, f);
  return f;
}

}  // namespace

CsdpSolveScope::CsdpSolveScope() {
  Cached() = {};
  ForgetSchurStructure();
  tls_in_solve_scope = true;
}

CsdpSolveScope::~CsdpSolveScope() {
  tls_in_solve_scope = false;
  Cached() = {};
  ForgetSchurStructure();
}

bool InCsdpSolveScope() { return tls_in_solve_scope; }

#ifdef HW_LIBSDP_OPERATORS
const char* CsdpOperators() { return "libsdp op_a, op_at (HWBOUNDS_LIBSDP_OPERATORS)"; }
}  // namespace hw::sdp
#else
const char* CsdpOperators() { return "hwbounds flat operators (sdp/csdp_operators.cpp)"; }

}  // namespace hw::sdp

// result[i] = A_i . X
extern "C" void op_a(int k, struct constraintmatrix* constraints, struct blockmatrix X, double* result) {
  hw::sdp::FlatOperators local;
  const auto& f = hw::sdp::FlatOf(k, constraints, local);
  for (int i = 1; i <= k; ++i) {
    double contrib = 0.0;
    for (int s = f.first_segment[i]; s < f.first_segment[i + 1]; ++s) {
      const auto& seg = f.segments[s];
      const struct blockrec& blk = X.blocks[seg.block];
      if (blk.blockcategory == DIAG) {
        const double* vec = blk.data.vec;
        for (int e = seg.begin; e < seg.end; ++e) contrib += f.entries[e].value * vec[f.entries[e].index];
      } else {
        const double* mat = blk.data.mat;
        for (int e = seg.begin; e < seg.end; ++e) {
          const auto& en = f.entries[e];
          contrib += en.p == en.q ? en.value * mat[en.p] : en.value * (mat[en.p] + mat[en.q]);
        }
      }
    }
    result[i] = 0.0;  // as CSDP: 0 + contrib (turns -0 into +0)
    result[i] += contrib;
  }
}

// result = sum_i y_i A_i
extern "C" void op_at(int k, double* y, struct constraintmatrix* constraints, struct blockmatrix result) {
  hw::sdp::FlatOperators local;
  const auto& f = hw::sdp::FlatOf(k, constraints, local);
  zero_mat(result);
  for (int i = 1; i <= k; ++i) {
    if (y[i] == 0.0) continue;
    for (int s = f.first_segment[i]; s < f.first_segment[i + 1]; ++s) {
      const auto& seg = f.segments[s];
      struct blockrec& blk = result.blocks[seg.block];
      if (blk.blockcategory == DIAG) {
        for (int e = seg.begin; e < seg.end; ++e) blk.data.vec[f.entries[e].index] += y[i] * f.entries[e].value;
      } else {
        for (int e = seg.begin; e < seg.end; ++e) {
          const auto& en = f.entries[e];
          blk.data.mat[en.p] += y[i] * en.value;
          if (en.p != en.q) blk.data.mat[en.q] += y[i] * en.value;
        }
      }
    }
  }
}
#endif  // HW_LIBSDP_OPERATORS
