#include "pop/relaxation_size.hpp"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>

#include <fmt/format.h>

namespace hw::pop {
namespace {

// C(n + d, n) in floating point: exact below 2^53, and no overflow for any order a user can type.
double MonomialCount(int n, int d) {
  if (d < 0) return 0.0;
  return std::round(std::exp(std::lgamma(n + d + 1.0) - std::lgamma(n + 1.0) - std::lgamma(d + 1.0)));
}

}  // namespace

double BytesPerBlockEntry(const std::string& solver) { return solver == "dsdp" ? 1100.0 : 240.0; }

RelaxationSize EstimateRelaxationSize(int num_vars, int order, const std::vector<int>& inequality_degrees,
                                      const std::vector<int>& equality_degrees, const std::string& solver) {
  RelaxationSize s;
  s.num_vars = num_vars;
  s.order = order;
  s.moments = MonomialCount(num_vars, 2 * order) - 1;
  s.moment_block = MonomialCount(num_vars, order);
  double squares = s.moment_block * s.moment_block;
  for (int d : inequality_degrees) {
    const int k = order - (std::max(0, d) + 1) / 2;
    if (k <= 0) {
      s.scalar_rows += 1;
      continue;
    }
    s.localizing_blocks.push_back(MonomialCount(num_vars, k));
    squares += s.localizing_blocks.back() * s.localizing_blocks.back();
  }
  for (int d : equality_degrees) s.equality_rows += MonomialCount(num_vars, std::max(0, 2 * order - std::max(0, d)));
  s.bytes = 8 * s.moments * s.moments + BytesPerBlockEntry(solver) * squares + 8 * s.moments * s.equality_rows;
  return s;
}

RelaxationSize EstimateRelaxationSize(const PolyProblem& problem, int order, const std::string& solver) {
  std::vector<int> g, h;
  for (const auto& p : problem.inequalities) g.push_back(p.degree());
  g.insert(g.end(), problem.box.size(), 2);
  for (const auto& p : problem.equalities) h.push_back(p.degree());
  return EstimateRelaxationSize(problem.num_vars, order, g, h, solver);
}

std::string FormatBytes(double bytes) {
  if (bytes < 1e6) return fmt::format("{:.0f} kB", bytes / 1e3);
  if (bytes < 1e9) return fmt::format("{:.0f} MB", bytes / 1e6);
  if (bytes < 1e13) return fmt::format("{:.1f} GB", bytes / 1e9);
  return fmt::format("{:.2g} GB", bytes / 1e9);
}

std::string RelaxationSize::describe() const {
  const double largest = localizing_blocks.empty() ? 0.0 : *std::max_element(localizing_blocks.begin(), localizing_blocks.end());
  return fmt::format("{:.6g} moments, moment matrix {:.6g} x {:.6g}, {} localizing blocks{}{}, estimated memory {} "
                     "(Schur complement 8 m^2 = {})",
                     moments, moment_block, moment_block, localizing_blocks.size(),
                     localizing_blocks.empty() ? "" : fmt::format(" up to {:.6g} x {:.6g}", largest, largest),
                     scalar_rows > 0 ? fmt::format(", {:.0f} scalar rows", scalar_rows) : "", FormatBytes(bytes),
                     FormatBytes(8 * moments * moments));
}

double AvailableMemoryBytes() {
  std::ifstream in("/proc/meminfo");
  std::string line;
  while (std::getline(in, line)) {
    std::istringstream ls(line);
    std::string key;
    double kb = 0;
    if (ls >> key >> kb && key == "MemAvailable:") return kb * 1024.0;
  }
  return static_cast<double>(::sysconf(_SC_PHYS_PAGES)) * static_cast<double>(::sysconf(_SC_PAGESIZE));
}

bool RelaxationFits(const PolyProblem& problem, int order, const std::string& solver, std::string* error) {
  const auto size = EstimateRelaxationSize(problem, order, solver);
  const double available = AvailableMemoryBytes();
  if (size.bytes <= available) return true;
  int fits = order;
  while (fits > problem.minimal_order() && EstimateRelaxationSize(problem, fits, solver).bytes > available) --fits;
  const auto largest = EstimateRelaxationSize(problem, fits, solver);
  if (error)
    *error = fmt::format(
        "order {}: the relaxation of this {}-variable problem is too large: {}, more than the {} of memory available; "
        "{}",
        order, problem.num_vars, size.describe(), FormatBytes(available),
        largest.bytes <= available ? fmt::format("the largest order that fits is {} ({})", fits, FormatBytes(largest.bytes))
                                   : "even the minimal order does not fit");
  return false;
}

}  // namespace hw::pop
