#pragma once
// The command line of paper_examples/cerone_tables: options into TablesOptions, every value checked.
#include <string>
#include <vector>

#include "paper_examples/cerone/tables_options.hpp"

namespace hw::cerone {

struct TablesCommand {
  TablesOptions options;
  std::string out = "out/cerone_tables";
  std::string text;  // the command line as given, for the outputs
};

// Parses `args` (without the program name). Returns 0 with *command set; 2 with *message set on an unknown
// option or an invalid value; 1 with the help text in *message for --help.
int ParseTablesCommand(const std::vector<std::string>& args, TablesCommand* command, std::string* message);

}  // namespace hw::cerone
