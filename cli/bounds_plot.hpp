#pragma once
// `hwbounds bounds --plot FILE.png`: a picture of a bounds run, drawn by gnuplot. Left, each interval in its
// prior box (0 = the box's lower edge, 1 = its upper edge); right, each interval stretched to its own width, with
// the range its certified feasible points reach (what the exact interval contains for certain). Both show the
// certified feasible points and, when given, the truth. With the exact set D (`bounds --set exact`), the left
// panel adds D's interval under each D^ss(n) one and the right panel stretches each of D's intervals to its own
// width, with the inner hull (points of D) inside it.
#include <string>
#include <vector>

#include "dss/set_membership.hpp"

namespace hw::cli {

// Before any work: InputError unless `path` ends in .png and can be written, and gnuplot with a PNG terminal
// (pngcairo, else png) is on the PATH. Returns that terminal's name.
std::string CheckPlotOutput(const std::string& path);

// The PNG of `summary` (bytes), drawn with `terminal` in a temporary directory that is removed afterwards.
// `truth` is empty or holds one value per parameter of summary.parameter_names. Throws std::runtime_error
// with gnuplot's messages when it fails.
// The exact set's intervals, one per parameter of summary.parameter_names (inner: NaN where unknown).
struct ExactPlotIntervals {
  std::vector<std::pair<double, double>> outer, inner;
};
std::string RenderBoundsPlot(const dss::BoundsSummary& summary, const std::vector<double>& truth,
                             const std::string& terminal, const ExactPlotIntervals* exact = nullptr);

}  // namespace hw::cli
