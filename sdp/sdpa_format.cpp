#include "sdp/sdpa_format.hpp"

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>

#include <fmt/format.h>

#include "core/atomic_write.hpp"
#include "core/input_error.hpp"

namespace hw::sdp {

std::string ToSdpaSparse(const LmiProblem& p) {
  std::string s = "* hwbounds LMI: min c'y s.t. sum y_i F_i - F_0 >= 0\n";
  s += fmt::format("* offset = {:.17g}\n", p.objective_offset);
  s += fmt::format("{} = mDIM\n{} = nBLOCK\n", p.num_vars(), p.blocks.size());
  for (std::size_t b = 0; b < p.blocks.size(); ++b)
    s += fmt::format("{}{}", b ? " " : "", p.blocks[b].kind == BlockSpec::Kind::kDiagonal ? -p.blocks[b].size : p.blocks[b].size);
  s += " = bLOCKsTRUCT\n";
  for (int i = 0; i < p.num_vars(); ++i) s += fmt::format("{}{:.17g}", i ? " " : "", p.c[i]);
  s += "\n";
  for (std::size_t i = 0; i < p.F.size(); ++i)
    for (const auto& e : p.F[i])
      s += fmt::format("{} {} {} {} {:.17g}\n", i, e.block + 1, e.row + 1, e.col + 1, e.value);
  return s;
}

void WriteSdpaSparse(const std::string& path, const LmiProblem& problem) {
  write_text_atomic(path, ToSdpaSparse(problem));
}

LmiProblem ParseSdpaSparse(const std::string& text, const std::string& source) {
  LmiProblem p;
  std::istringstream in(text);
  std::string line;
  int line_no = 0, stage = 0, m = 0, nblocks = 0;
  auto fail = [&](const std::string& why) { throw InputError(fmt::format("{}:{}: {}", source, line_no, why)); };
  // Header values may share lines and be separated by commas, braces or parentheses.
  std::vector<double> header;
  while (std::getline(in, line)) {
    ++line_no;
    if (line.empty() || line[0] == '*' || line[0] == '"') {
      const auto at = line.find("offset =");
      if (at != std::string::npos) {
        const std::string rest = line.substr(at + 8);
        char* end = nullptr;
        p.objective_offset = std::strtod(rest.c_str(), &end);
        if (end == rest.c_str() || !std::isfinite(p.objective_offset))
          fail("expected a finite number after '* offset ='");
      }
      continue;
    }
    if (stage < 4) {
      std::string clean;
      for (char c : line) clean += (c == ',' || c == '{' || c == '}' || c == '(' || c == ')') ? ' ' : c;
      if (auto eq = clean.find('='); eq != std::string::npos) clean = clean.substr(0, eq);
      std::istringstream ls(clean);
      double v;
      std::vector<double> vals;
      while (ls >> v) vals.push_back(v);
      if (stage == 0) {
        if (vals.empty()) fail("expected the number of variables mDIM");
        m = static_cast<int>(vals[0]);
        if (m < 0 || vals[0] != m) fail("mDIM must be a non-negative integer");
        stage = 1;
      } else if (stage == 1) {
        if (vals.empty()) fail("expected the number of blocks nBLOCK");
        nblocks = static_cast<int>(vals[0]);
        if (nblocks <= 0) fail("nBLOCK must be a positive integer");
        stage = 2;
      } else if (stage == 2) {
        header.insert(header.end(), vals.begin(), vals.end());
        if (static_cast<int>(header.size()) >= nblocks) {
          if (static_cast<int>(header.size()) > nblocks) fail(fmt::format("expected {} block sizes", nblocks));
          for (double b : header) {
            if (b == 0 || b != std::floor(b)) fail("block sizes must be non-zero integers (negative = diagonal)");
            p.blocks.push_back({b < 0 ? BlockSpec::Kind::kDiagonal : BlockSpec::Kind::kPsd, static_cast<int>(std::abs(b))});
          }
          header.clear();
          stage = m > 0 ? 3 : 4;
        }
      } else {
        header.insert(header.end(), vals.begin(), vals.end());
        if (static_cast<int>(header.size()) >= m) {
          if (static_cast<int>(header.size()) > m) fail(fmt::format("expected {} objective coefficients", m));
          p.c = header;
          stage = 4;
          p.F.assign(m + 1, {});
        }
      }
      if (stage == 4 && p.F.empty()) p.F.assign(m + 1, {});
      continue;
    }
    std::istringstream ls(line);
    long mat, blk, i, j;
    double v;
    if (!(ls >> mat >> blk >> i >> j >> v)) fail("expected an entry 'matno blkno i j value'");
    if (mat < 0 || mat > m) fail(fmt::format("matrix number {} outside 0..{}", mat, m));
    if (blk < 1 || blk > nblocks) fail(fmt::format("block number {} outside 1..{}", blk, nblocks));
    const int size = p.blocks[blk - 1].size;
    if (i < 1 || j < 1 || i > size || j > size) fail(fmt::format("entry ({}, {}) outside a {}x{} block", i, j, size, size));
    if (i > j) std::swap(i, j);
    if (p.blocks[blk - 1].kind == BlockSpec::Kind::kDiagonal && i != j) fail("off-diagonal entry in a diagonal block");
    p.F[mat].push_back({static_cast<int32_t>(blk - 1), static_cast<int32_t>(i - 1), static_cast<int32_t>(j - 1), v});
  }
  if (stage < 4) throw InputError(fmt::format("{}: ended before the header was complete (mDIM, nBLOCK, block sizes, c)", source));
  std::string error;
  if (!p.IsValid(&error)) throw InputError(fmt::format("{}: {}", source, error));
  return p;
}

LmiProblem ReadSdpaSparse(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw InputError(fmt::format("{}: cannot open", path));
  std::stringstream ss;
  ss << in.rdbuf();
  return ParseSdpaSparse(ss.str(), path);
}

}  // namespace hw::sdp
