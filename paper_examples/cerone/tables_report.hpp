#pragma once
// The tables' outputs: DIR/tables.md, DIR/tables.json, and a plot per realisation (intervals_snr<S>_seed<K>.png,
// from a gnuplot script and data file beside it).
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "paper_examples/cerone/equivalent_snr.hpp"
#include "paper_examples/cerone/table_case.hpp"
#include "paper_examples/cerone/table_properties.hpp"
#include "paper_examples/cerone/tables_options.hpp"

namespace hw::cerone {

struct TablesReport {
  std::string command;  // the command line that produced it
  TablesOptions options;
  std::vector<TableCase> cases;
  std::vector<Violation> violations;
  std::optional<EquivalentSnrResult> equivalent;
};

std::string TablesMarkdown(const TablesReport& report);
nlohmann::json TablesJson(const TablesReport& report);

// The plot of one realisation: per parameter and horizon, the inner hull, the paper's interval and the outer
// interval of each order, minus the truth, in units of the paper's half-width (of the inner hull's where the
// paper prints none).
struct PlotFiles {
  std::string stem;    // "intervals_snr31_seed1"
  std::string data;    // the .dat file
  std::string script;  // the .gp file, writing stem + ".png"
};
std::vector<PlotFiles> TablesPlots(const TablesReport& report);

// Writes every output into `dir` (atomically) and runs gnuplot on each plot; returns the messages to print
// (a missing gnuplot is a message, the data files stay).
std::vector<std::string> WriteTables(const std::string& dir, const TablesReport& report);

}  // namespace hw::cerone
