// Tables I-III of paper 001 (Cerone, Piga, Regruto), reproduced honestly: for every realisation (SNR, seed) and
// dynamic horizon n, the engine's outer intervals (relaxation orders delta), the inner hull of D^ss(n) (certified
// feasible points from many local searches), the paper's interval and the truth, with the properties every table
// must have checked (paper_examples/cerone/table_properties.hpp), and optionally the equivalent noise level at
// which our inner hulls are as wide as the paper's intervals (paper_examples/cerone/equivalent_snr.hpp).
//
//   cerone_tables [--out DIR] [--horizons 2,3] [--orders 2,3] [--outer-orders 2|none] [--snr-list 31,35,40,45]
//                 [--outer-snr 31] [--seeds 1,2,3] [--samples 1000] [--params a1,b1] [--solver auto] [--threads T]
//                 [--run-dir DIR] [--row-block-order K] [--inner-starts 2] [--equivalent-snr] ...
// (options: paper_examples/cerone/tables_cli.cpp, or --help). Writes DIR/tables.md, DIR/tables.json and
// DIR/intervals_snr<S>_seed<K>.png (gnuplot). Exit status: 0 when every property holds, 3 when one is violated
// (listed in the outputs), 2 on invalid options.
#include <filesystem>

#include <fmt/format.h>

#include "paper_examples/cerone/table_properties.hpp"
#include "paper_examples/cerone/tables_cli.hpp"
#include "paper_examples/cerone/tables_report.hpp"
#include "paper_examples/cerone/tables_run.hpp"

int main(int argc, char** argv) {
  hw::cerone::TablesCommand command;
  std::string message;
  const int parsed = hw::cerone::ParseTablesCommand(std::vector<std::string>(argv + 1, argv + argc), &command, &message);
  if (parsed == 1) return fmt::print("{}", message), 0;
  if (parsed != 0) return fmt::print(stderr, "cerone_tables: {}\n", message), 2;
  const auto& options = command.options;
  std::filesystem::create_directories(command.out);
  const hw::cerone::Log log = [](const std::string& line) { fmt::print(stderr, "{}\n", line); };
  hw::cerone::TablesReport report;
  report.command = command.text;
  report.options = options;
  report.cases = hw::cerone::RunTables(options, log);
  report.violations = hw::cerone::CheckTableProperties(report.cases, options.tolerance);
  if (options.equivalent_snr)
    report.equivalent = hw::cerone::FindEquivalentSnr(options.equivalent, [&](double snr) {
      return hw::cerone::InnerWidthRatios(options, snr, options.equivalent_seed, log);
    });
  for (const auto& line : hw::cerone::WriteTables(command.out, report)) fmt::print(stderr, "{}\n", line);
  fmt::print("{}", hw::cerone::TablesMarkdown(report));
  if (!report.violations.empty())
    fmt::print(stderr, "cerone_tables: {} property violations (see {}/tables.md)\n", report.violations.size(), command.out);
  return report.violations.empty() ? 0 : 3;
}
