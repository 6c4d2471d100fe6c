#pragma once
// The size of a moment relaxation, computed from counts alone (no monomial basis is built), so that a
// relaxation that cannot fit in memory is refused with its numbers before any allocation.
//
// Memory model (bytes): the backends form and factor the dense Schur complement of the m free moments,
// 8 m^2; per entry of every PSD block (b^2 for a b x b block) they keep dense iterates, steps, work space and
// the constraint data, measured at about 240 bytes for CSDP and SDPA and up to 1100 for DSDP (which also
// stores the per-moment data matrices of a block densely when they are dense enough); the equality
// elimination holds one dense row of m per equality row, 8 m r. Calibrated against peak resident memory
// (tests/relaxation_size_test.cpp lists the measurements): the estimate is 0.95-1.2x of the measured peak
// for CSDP and SDPA, 1-2.6x for DSDP.
#include <string>
#include <vector>

#include "pop/moment_relaxation.hpp"

namespace hw::pop {

struct RelaxationSize {
  int num_vars = 0, order = 0;
  double moments = 0;       // free moment variables m = C(n + 2 delta, n) - 1
  double moment_block = 0;  // C(n + delta, n)
  std::vector<double> localizing_blocks;  // PSD localizing blocks (one per inequality of order >= 1)
  double scalar_rows = 0;   // localizers of order 0, gathered into one diagonal block
  double equality_rows = 0;
  double bytes = 0;         // the memory model above, for the solver named in the estimate
  std::string describe() const;  // "N moments, moment matrix S x S, K localizing blocks up to B, ~X GB"
};

// From the number of variables and the degrees of the inequalities (box constraints included, degree 2 each)
// and of the equalities.
// `solver` is "csdp", "sdpa" or "dsdp" (the memory per block entry differs, see above).
RelaxationSize EstimateRelaxationSize(int num_vars, int order, const std::vector<int>& inequality_degrees,
                                      const std::vector<int>& equality_degrees, const std::string& solver = "sdpa");
RelaxationSize EstimateRelaxationSize(const PolyProblem& problem, int order, const std::string& solver = "sdpa");
// Bytes per entry of a PSD block that a solve with this backend holds (the memory model above).
double BytesPerBlockEntry(const std::string& solver);

// True when the order-`order` relaxation of `problem` fits in the memory available now; false with the numbers
// (its size, the memory available, the largest order that fits) in *error otherwise. Computed from counts, before
// anything is allocated; the CLI and the Python module refuse with this message.
bool RelaxationFits(const PolyProblem& problem, int order, const std::string& solver, std::string* error);

// Memory the system reports available now (MemAvailable of /proc/meminfo; physical memory when absent).
double AvailableMemoryBytes();
// "1.5 GB", "320 MB", "2.1e+12 GB".
std::string FormatBytes(double bytes);

}  // namespace hw::pop
