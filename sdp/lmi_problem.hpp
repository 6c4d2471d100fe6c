#pragma once
// The solver-neutral LMI problem of hwbounds, in "free-variable" (inequality) form:
//
//     minimize    c^T y
//     subject to  F(y) = sum_{i=1..m} y_i F_i - F_0  is positive semidefinite,
//
// with every F_i symmetric and block diagonal. Blocks are PSD blocks or diagonal (LP) blocks.
// y is free: this is CSDP's dual problem (C = F_0, A_i = F_i, a = c) and SDPA's primal problem
// (the SDPA-format's own convention), so neither backend ever splits a free variable in two.
// The multiplier X >= 0 of the LMI proves the lower bound  F_0 . X  (when F_i . X = c_i for all i):
// that is the value reported as a guaranteed lower bound after a solve.
#include <cstdint>
#include <string>
#include <vector>

namespace hw::sdp {

struct BlockSpec {
  enum class Kind { kPsd, kDiagonal };
  Kind kind = Kind::kPsd;
  int size = 0;
};

// One upper-triangular entry (row <= col, 0-based) of one block of one matrix.
struct Entry {
  int32_t block = 0;
  int32_t row = 0;
  int32_t col = 0;
  double value = 0.0;
};

struct LmiProblem {
  std::vector<BlockSpec> blocks;
  std::vector<double> c;                   // objective, size m
  std::vector<std::vector<Entry>> F;       // F[0] = F_0, F[i] = F_i (i = 1..m); size m + 1
  double objective_offset = 0.0;           // reported values are c^T y + offset

  int num_vars() const { return static_cast<int>(c.size()); }
  // Checks sizes, indices, triangularity (diagonal blocks: row == col) and finiteness.
  bool IsValid(std::string* error) const;
  // Convenience: adds value to entry (block,row,col) of matrix i (i = 0 for F_0); symmetric, so
  // (row,col) is stored in upper-triangular order.
  void add(int matrix, int block, int row, int col, double value);
  std::size_t nonzeros() const;
};

}  // namespace hw::sdp
