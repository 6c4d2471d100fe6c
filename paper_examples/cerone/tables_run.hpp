#pragma once
// Computing the tables' cases: a realisation per (SNR, seed), its inner hulls per horizon, and the engine's outer
// intervals where TablesOptions asks for them.
#include <functional>
#include <string>
#include <vector>

#include "core/cerone_example.hpp"
#include "paper_examples/cerone/equivalent_snr.hpp"
#include "paper_examples/cerone/table_case.hpp"
#include "paper_examples/cerone/tables_options.hpp"

namespace hw::cerone {

using Log = std::function<void(const std::string&)>;

// D^ss(n) of a realisation in the prior box [-box, box]^8.
dss::HwOuterSet ExampleSet(const CeroneExample& ex, int horizon, double box);

// Layout indices of the named parameters (empty names: every parameter).
std::vector<int> ParameterIndices(const dss::HwOuterSet& set, const std::vector<std::string>& names);

// The box of a case's outer intervals: per parameter the intersection of its runs' intervals (each is a valid
// outer bound) with the case's own starting box, each interval widened outward by 1e-9 of its width against
// rounding. Parameters without an interval keep the starting box.
std::vector<std::pair<double, double>> OuterIntervalBox(const TableCase& c);

// One case: the realisation (seed, SNR), its inner hull at horizon n, and the outer runs wanted there. The
// outer runs start in OuterIntervalBox(*shorter) when given (a shorter horizon's case of the same realisation
// with outer runs), else in the prior box; the inner hull always searches the prior box.
TableCase RunCase(const TablesOptions& options, int horizon, double snr_db, uint64_t seed, const Log& log,
                  const TableCase* shorter = nullptr);

// Every case of the tables, in the order (SNR, seed, horizon ascending); with options.nest_horizons each
// horizon's outer runs start in the outer box of the one before it.
std::vector<TableCase> RunTables(const TablesOptions& options, const Log& log);

// Inner half-widths over the paper's ones at one SNR (the horizons of `options` the paper prints), for the
// equivalent-SNR bisection.
std::vector<WidthRatio> InnerWidthRatios(const TablesOptions& options, double snr_db, uint64_t seed, const Log& log);

}  // namespace hw::cerone
