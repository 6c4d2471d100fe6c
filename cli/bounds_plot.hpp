#pragma once
// `hwbounds bounds --plot FILE.png`: a picture of a bounds run, drawn by gnuplot. Left, each interval in its
// prior box (0 = the box's lower edge, 1 = its upper edge); right, each interval stretched to its own width, with
// the range its certified feasible points reach (what the exact interval contains for certain). Both show the
// certified feasible points and, when given, the truth.
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
std::string RenderBoundsPlot(const dss::BoundsSummary& summary, const std::vector<double>& truth,
                             const std::string& terminal);

}  // namespace hw::cli
