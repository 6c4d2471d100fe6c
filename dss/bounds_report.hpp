#pragma once
// A bounds run's result for a person (Ceres' Summary::BriefReport / FullReport): the text `hwbounds bounds`
// prints after a run, and the Python module's `bounds(..., report=True)` returns, from one place.
#include <string>
#include <vector>

#include "dss/set_membership.hpp"

namespace hw::dss {

struct BoundsReportOptions {
  // Empty, or one true value per parameter of summary.parameter_names: each row says inside or OUTSIDE.
  std::vector<double> truth;
  // The model class the verdict of an invalidated model names, e.g. "na = 2, nb = 2, input basis poly:3, output
  // basis poly:3, horizon 2"; empty: the horizon only.
  std::string model_class;
  bool verify = true;  // the run verified its bounds (its cost is reported; unverified endpoints are warned of)
};

// Every given true value lies inside its interval (true without a truth).
bool TruthCovered(const BoundsSummary& summary, const std::vector<double>& truth);

// The interval table and the warnings, or for an invalidated model the verdict with its certificates.
std::string BriefReport(const BoundsSummary& summary, const BoundsReportOptions& options);

// Everything: the table or the verdict, the pieces of a split box, the automatic rounds, the run's summary
// (prior and contracted boxes, counts, times, row reduction, where the bounds came from), the warnings and the
// largest part of an interval no certified feasible point reaches.
std::string FullReport(const BoundsSummary& summary, const BoundsReportOptions& options);

}  // namespace hw::dss
