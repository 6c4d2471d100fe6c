#pragma once
// SDPA sparse format (.dat-s) for LmiProblem, so any problem can be checked with other solvers
// (e.g. the `csdp` and `sdpa` binaries). Layout: m, nBlocks, block sizes (negative = diagonal/LP),
// c_1..c_m, then lines "matno blkno i j value" (1-based, upper triangle, matno 0 = F_0).
// The objective offset, which the format lacks, travels in a comment line "* offset = <value>".
#include <string>

#include "sdp/lmi_problem.hpp"

namespace hw::sdp {

std::string ToSdpaSparse(const LmiProblem& problem);
void WriteSdpaSparse(const std::string& path, const LmiProblem& problem);  // atomic
// Throws hw::InputError naming the file, the line and what was expected.
LmiProblem ParseSdpaSparse(const std::string& text, const std::string& source);
LmiProblem ReadSdpaSparse(const std::string& path);

}  // namespace hw::sdp
