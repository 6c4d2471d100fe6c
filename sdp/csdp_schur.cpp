#include "sdp/csdp_schur.hpp"

#include "sdp/csdp_operators.hpp"

#include <algorithm>
#include <vector>

#include <Eigen/Dense>

extern "C" {
#include <csdp/declarations.h>
}

// CSDP's Schur complement O_ij = tr(A_i Z^-1 A_j X), assembled per block in a form that suits the moment
// relaxations' LMIs. CSDP's own op_o() visits every pair of constraints that share a block and sums products of
// their entries; a 9 x 9 localizing block touches hundreds to a thousand moments, so most of a solve went into
// those pair loops (77-86 % of CSDP's time on the set-membership relaxations, perf). Here a block's
// contribution is A_B K_B A_B^T with A_B sparse (constraints x packed entries) and K_B dense, which costs
// (constraints in the block) x (nonzeros of the block) instead of (constraints in the block)^2 x (entries per
// constraint)^2. Linked before the static libsdp.a (sdp/CMakeLists.txt), this definition replaces the archive's
// op_o() as initparams() does (csdp_backend.cpp); only the upper triangle of O is read by CSDP.
namespace hw::sdp {
namespace {

using Matrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::ColMajor>;
// CSDP's dense blocks, read in place (Fortran order).
using BlockView = Eigen::Map<const Matrix>;

// A block at most this size gets the dense packed kernel K_B (P x P, P = n (n + 1) / 2); larger blocks (the
// order-3 moment matrix, 165 x 165) get W = Z^-1 A_i X per constraint.
constexpr int kPackedKernelMaxSize = 46;

// Packed index of (r, c), r <= c, 0-based.
int Packed(int r, int c) { return r + c * (c + 1) / 2; }

// One constraint's entries in one block, positions 0-based.
struct BlockConstraint {
  int constraint = 0;  // 1-based, as CSDP numbers them
  std::vector<int> row, col, packed;
  std::vector<double> value;
};

std::vector<BlockConstraint> ConstraintsOfBlock(struct sparseblock* first) {
  std::vector<BlockConstraint> out;
  for (struct sparseblock* p = first; p != nullptr; p = p->nextbyblock) {
    BlockConstraint c;
    c.constraint = p->constraintnum;
    for (int e = 1; e <= p->numentries; ++e) {
      c.row.push_back(std::min(p->iindices[e], p->jindices[e]) - 1);
      c.col.push_back(std::max(p->iindices[e], p->jindices[e]) - 1);
      c.packed.push_back(Packed(c.row.back(), c.col.back()));
      c.value.push_back(p->entries[e]);
    }
    out.push_back(std::move(c));
  }
  // Ascending constraint numbers: a block's pairs (i <= j) then fill column j of O's upper triangle in order.
  std::sort(out.begin(), out.end(), [](const auto& a, const auto& b) { return a.constraint < b.constraint; });
  return out;
}

// A block's constraints, also as flat arrays (constraint c's entries at [start[c], start[c + 1])) for the loops
// that visit every entry many times.
struct BlockData {
  std::vector<BlockConstraint> constraints;  // ascending constraint numbers
  std::vector<int> start, packed;
  std::vector<double> value;
};

BlockData DataOfBlock(struct sparseblock* first) {
  BlockData d;
  d.constraints = ConstraintsOfBlock(first);
  d.start.push_back(0);
  for (const auto& c : d.constraints) {
    d.packed.insert(d.packed.end(), c.packed.begin(), c.packed.end());
    d.value.insert(d.value.end(), c.value.begin(), c.value.end());
    d.start.push_back(static_cast<int>(d.value.size()));
  }
  return d;
}

// The constraints of every block, read once per solve: the structure does not change between iterations, and
// rebuilding it in every op_o() call cost about a fifth of the assembly (allocation included; perf on the
// bundled example). Kept only inside a CsdpSolveScope (csdp_operators.hpp), whose ends drop it, so a later solve
// never sees an earlier solve's structure.
struct SchurStructure {
  struct sparseblock** byblocks = nullptr;
  int k = 0;
  std::vector<BlockData> blocks;  // 1-based like CSDP's blocks
};
SchurStructure& CachedStructure() {
  static SchurStructure structure;
  return structure;
}

// The solve's cached structure inside a CsdpSolveScope, else `local` filled for this call.
const std::vector<BlockData>& StructureOf(int k, struct sparseblock** byblocks, int nblocks, SchurStructure& local) {
  SchurStructure& s = InCsdpSolveScope() ? CachedStructure() : local;
  if (s.byblocks != byblocks || s.k != k || static_cast<int>(s.blocks.size()) != nblocks + 1) {
    s.byblocks = byblocks;
    s.k = k;
    s.blocks.assign(nblocks + 1, {});
    for (int b = 1; b <= nblocks; ++b)
      if (byblocks[b] != nullptr) s.blocks[b] = DataOfBlock(byblocks[b]);
  }
  return s.blocks;
}

class SchurMatrix {
 public:
  SchurMatrix(int k, double* o) : k_(k), ld_(k % 2 == 0 ? k + 1 : k), o_(o) {}
  void Zero() { std::fill(o_, o_ + static_cast<long>(ld_) * k_, 0.0); }
  // Adds v to O(i, j) and (for i != j) O(j, i), stored in the upper triangle; i, j 1-based.
  void Add(int i, int j, double v) {
    if (i > j) std::swap(i, j);
    o_[(static_cast<long>(j) - 1) * ld_ + i - 1] += v;
  }
  // Column j (1-based) of the stored upper triangle, indexed by i - 1.
  double* Column(int j) { return o_ + (static_cast<long>(j) - 1) * ld_; }
  // A large block writes row i's terms down column i of the (otherwise unused) lower triangle, contiguously; this
  // adds each strictly lower (j, i) into (i, j) and clears it. `index` (0-based, ascending) are the block's
  // constraints; tiles keep both reads in cache.
  void FoldLowerIntoUpper(const std::vector<int>& index) {
    constexpr int kTile = 32;
    const int m = static_cast<int>(index.size());
    for (int j0 = 0; j0 < m; j0 += kTile)
      for (int i0 = 0; i0 <= j0; i0 += kTile)
        for (int j = j0; j < std::min(j0 + kTile, m); ++j) {
          double* upper = o_ + static_cast<long>(index[j]) * ld_;
          for (int i = i0; i < std::min(i0 + kTile, j); ++i) {
            double& lower = o_[static_cast<long>(index[i]) * ld_ + index[j]];
            upper[index[i]] += lower;
            lower = 0.0;
          }
        }
  }

 private:
  int k_, ld_;
  double* o_;
};

// Diagonal (LP) block: O_ij += sum_p A_i[p] A_j[p] Z^-1[p] X[p], by position.
void AddDiagonalBlock(const std::vector<BlockConstraint>& cs, const double* zi, const double* x, int n,
                      SchurMatrix& o) {
  std::vector<std::vector<std::pair<int, double>>> at(n);
  for (const auto& c : cs)
    for (std::size_t e = 0; e < c.value.size(); ++e) at[c.row[e]].push_back({c.constraint, c.value[e]});
  for (int p = 0; p < n; ++p) {
    const double d = zi[p + 1] * x[p + 1];
    const auto& list = at[p];
    for (std::size_t a = 0; a < list.size(); ++a)
      for (std::size_t b = a; b < list.size(); ++b) o.Add(list[a].first, list[b].first, list[a].second * list[b].second * d);
  }
}

// K(u, v) = tr(E_u Z^-1 E_v X) over packed positions u = (p, q), v = (r, s) of an n x n block, with E_u the
// symmetric unit matrix of u.
Matrix PackedKernel(const BlockView& zi, const BlockView& x) {
  const int n = static_cast<int>(zi.rows());
  const int packed = n * (n + 1) / 2;
  std::vector<int> pr(packed), pc(packed);
  for (int c = 0; c < n; ++c)
    for (int r = 0; r <= c; ++r) pr[Packed(r, c)] = r, pc[Packed(r, c)] = c;
  Matrix kernel(packed, packed);
  for (int v = 0; v < packed; ++v) {
    const int r = pr[v], s = pc[v];
    for (int u = 0; u <= v; ++u) {
      const int p = pr[u], q = pc[u];
      // Orientations (a, b) of u and (c, d) of v: sum of Z^-1[b, c] X[d, a].
      double sum = zi(q, r) * x(s, p);
      if (p != q) sum += zi(p, r) * x(s, q);
      if (r != s) sum += zi(q, s) * x(r, p);
      if (p != q && r != s) sum += zi(p, s) * x(r, q);
      kernel(u, v) = kernel(v, u) = sum;
    }
  }
  return kernel;
}

// Small matrix block: U = A_B K, then O_ij += A_j . U_i.
void AddSmallMatrixBlock(const BlockData& block, const BlockView& zi, const BlockView& x, SchurMatrix& o) {
  const auto& cs = block.constraints;
  const Matrix kernel = PackedKernel(zi, x);
  const int packed = static_cast<int>(kernel.rows());
  // U = A_B K (constraints x packed positions), one column at a time: U(i, p) = sum over A_i's entries of
  // value * K(position, p), reading one column of K (a transpose of A_B K built by rows cost more than this).
  const int m = static_cast<int>(cs.size());
  Matrix u(m, packed);
  for (int p = 0; p < packed; ++p) {
    const double* k_column = kernel.col(p).data();
    double* u_column = u.col(p).data();
    for (int i = 0; i < m; ++i) {
      double sum = 0.0;
      for (int e = block.start[i]; e < block.start[i + 1]; ++e) sum += block.value[e] * k_column[block.packed[e]];
      u_column[i] = sum;
    }
  }
  // Column j of the block's contribution, rows i <= j: sum over A_j's entries of value * U(:, position). The
  // constraints ascend, so (i, j) lies in O's upper triangle; their rows in O are read from one contiguous array.
  std::vector<int> row_in_o(m);
  for (int i = 0; i < m; ++i) row_in_o[i] = cs[i].constraint - 1;
  Eigen::VectorXd column(m);
  for (int j = 0; j < m; ++j) {
    column.head(j + 1).setZero();
    for (std::size_t e = 0; e < cs[j].value.size(); ++e)
      column.head(j + 1) += cs[j].value[e] * u.col(cs[j].packed[e]).head(j + 1);
    double* o_column = o.Column(cs[j].constraint);
    for (int i = 0; i <= j; ++i) o_column[row_in_o[i]] += column[i];
  }
}

// Large matrix block: per constraint i, W = Z^-1 A_i X from the rows A_i touches, then O_ij += A_j . W.
void AddLargeMatrixBlock(const std::vector<BlockConstraint>& cs, const BlockView& zi, const BlockView& x,
                         SchurMatrix& o) {
  const int n = static_cast<int>(zi.rows());
  const int m = static_cast<int>(cs.size());
  Matrix w(n, n), t, zsub;
  std::vector<int> rows, slot(n, -1);
  for (int i = 0; i < m; ++i) {
    const auto& a = cs[i];
    rows.clear();
    for (std::size_t e = 0; e < a.value.size(); ++e)
      for (int r : {a.row[e], a.col[e]})
        if (slot[r] < 0) slot[r] = static_cast<int>(rows.size()), rows.push_back(r);
    const int nr = static_cast<int>(rows.size());
    t.setZero(nr, n);  // (A_i X) restricted to the rows A_i touches
    for (std::size_t e = 0; e < a.value.size(); ++e) {
      const int p = a.row[e], q = a.col[e];
      t.row(slot[p]) += a.value[e] * x.row(q);
      if (p != q) t.row(slot[q]) += a.value[e] * x.row(p);
    }
    zsub.resize(n, nr);
    for (int r = 0; r < nr; ++r) zsub.col(r) = zi.col(rows[r]);
    w.noalias() = zsub * t;
    for (int r : rows) slot[r] = -1;
    // O(i, j), j >= i, goes to (j, i) in column i: contiguous writes (row-wise ones into the upper triangle missed
    // the cache at every j); FoldLowerIntoUpper moves them up. The diagonal is the same element either way.
    double* lower_column = o.Column(a.constraint);
    for (int j = i; j < m; ++j) {
      double sum = 0.0;
      for (std::size_t e = 0; e < cs[j].value.size(); ++e) {
        const int r = cs[j].row[e], s = cs[j].col[e];
        sum += cs[j].value[e] * (r == s ? w(r, s) : w(r, s) + w(s, r));
      }
      lower_column[cs[j].constraint - 1] += sum;
    }
  }
  std::vector<int> index(m);
  for (int i = 0; i < m; ++i) index[i] = cs[i].constraint - 1;
  o.FoldLowerIntoUpper(index);
}

BlockView View(const struct blockrec& block) {
  return BlockView(block.data.mat, block.blocksize, block.blocksize);
}

}  // namespace

void ForgetSchurStructure() { CachedStructure() = {}; }

#ifdef HW_LIBSDP_SCHUR
const char* CsdpSchurAssembly() { return "libsdp op_o (HWBOUNDS_LIBSDP_SCHUR)"; }
}  // namespace hw::sdp
#else
const char* CsdpSchurAssembly() { return "hwbounds block kernels (sdp/csdp_schur.cpp)"; }

}  // namespace hw::sdp

extern "C" void op_o(int k, struct constraintmatrix* /*constraints*/, struct sparseblock** byblocks,
                     struct blockmatrix Zi, struct blockmatrix X, double* O, struct blockmatrix /*work1*/,
                     struct blockmatrix /*work2*/) {
  using namespace hw::sdp;
  SchurMatrix o(k, O);
  o.Zero();
  SchurStructure local;
  const auto& structure = StructureOf(k, byblocks, X.nblocks, local);
  for (int b = 1; b <= X.nblocks; ++b) {
    if (byblocks[b] == nullptr) continue;
    const auto& block = structure[b];
    const auto& cs = block.constraints;
    const struct blockrec& xb = X.blocks[b];
    if (xb.blockcategory == DIAG) {
      AddDiagonalBlock(cs, Zi.blocks[b].data.vec, xb.data.vec, xb.blocksize, o);
    } else if (xb.blocksize <= kPackedKernelMaxSize) {
      AddSmallMatrixBlock(block, View(Zi.blocks[b]), View(xb), o);
    } else {
      AddLargeMatrixBlock(cs, View(Zi.blocks[b]), View(xb), o);
    }
  }
}
#endif  // HW_LIBSDP_SCHUR
