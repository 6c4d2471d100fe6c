#pragma once
// Each subcommand lives in its own cli/cmd_<name>.cpp and registers itself on the root app.
// A command's callback throws hw::InputError for bad user input; main() turns that into a
// message on stderr and exit code 2.
#include <string>

#include <CLI/CLI.hpp>

#include "core/input_error.hpp"

namespace hw::cli {

// Runs a check the library shares with the Python module (`check(&message)` is false for a bad value) and
// reports its message as bad input after the option it concerns: "--order: order 1 is below ...". The
// Python module raises the same message as ValueError.
template <typename Check>
void RequireOption(const std::string& option, Check&& check) {
  std::string error;
  if (!check(&error)) throw InputError(option + ": " + error);
}

// Thrown by a command after it has written its results, to end with a documented non-zero exit status
// (e.g. `bounds`: 3 when the data invalidate the model).
struct CommandExit {
  int code = 1;
};

void AddSimulateCommand(CLI::App& app);
void AddPopCommand(CLI::App& app);
void AddBoundsCommand(CLI::App& app);
void AddDiagnoseCommand(CLI::App& app);
void AddScenarioCommand(CLI::App& app);
void AddBrouriCommand(CLI::App& app);
void AddEsmaeilaniCommand(CLI::App& app);
void AddCompareCommand(CLI::App& app);
// Further commands are declared here as their modules land (bounds, brouri, esmaeilani, diagnose, compare).

}  // namespace hw::cli
