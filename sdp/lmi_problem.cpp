#include "sdp/lmi_problem.hpp"

#include <cmath>

#include <fmt/format.h>

namespace hw::sdp {

bool LmiProblem::IsValid(std::string* error) const {
  auto fail = [&](std::string m) {
    if (error) *error = std::move(m);
    return false;
  };
  if (blocks.empty()) return fail("the LMI has no blocks");
  for (std::size_t b = 0; b < blocks.size(); ++b)
    if (blocks[b].size <= 0) return fail(fmt::format("block {} has size {}", b, blocks[b].size));
  if (F.size() != c.size() + 1)
    return fail(fmt::format("{} matrices for {} variables; expected F_0..F_m ({} matrices)", F.size(), c.size(),
                            c.size() + 1));
  for (std::size_t i = 0; i < c.size(); ++i)
    if (!std::isfinite(c[i])) return fail(fmt::format("objective coefficient {} is not finite", i + 1));
  if (!std::isfinite(objective_offset)) return fail("objective offset is not finite");
  for (std::size_t i = 0; i < F.size(); ++i) {
    for (const auto& e : F[i]) {
      if (e.block < 0 || e.block >= static_cast<int>(blocks.size()))
        return fail(fmt::format("F_{} has an entry in block {} of {}", i, e.block, blocks.size()));
      const auto& spec = blocks[e.block];
      if (e.row < 0 || e.col < e.row || e.col >= spec.size)
        return fail(fmt::format("F_{} block {} entry ({}, {}) is outside the upper triangle of a {}x{} block", i,
                                e.block, e.row, e.col, spec.size, spec.size));
      if (spec.kind == BlockSpec::Kind::kDiagonal && e.row != e.col)
        return fail(fmt::format("F_{} block {} is diagonal but has entry ({}, {})", i, e.block, e.row, e.col));
      if (!std::isfinite(e.value)) return fail(fmt::format("F_{} block {} has a non-finite entry", i, e.block));
    }
  }
  return true;
}

void LmiProblem::add(int matrix, int block, int row, int col, double value) {
  if (row > col) std::swap(row, col);
  if (matrix >= static_cast<int>(F.size())) F.resize(matrix + 1);
  F[matrix].push_back({block, row, col, value});
}

std::size_t LmiProblem::nonzeros() const {
  std::size_t n = 0;
  for (const auto& m : F) n += m.size();
  return n;
}

}  // namespace hw::sdp
