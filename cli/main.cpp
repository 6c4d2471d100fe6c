// hwbounds: guaranteed parameter bounds and point estimators for Hammerstein–Wiener systems.
#include <cstdio>
#include <exception>

#include <fmt/format.h>

#include "cli/commands.hpp"
#include "core/input_error.hpp"

int main(int argc, char** argv) {
  CLI::App app{"hwbounds: set-membership bounds, estimators and diagnosis for Hammerstein-Wiener systems"};
  app.require_subcommand(1);
  // Every option's help shows its default; options whose default is computed say how (default_str).
  app.option_defaults()->always_capture_default();
  hw::cli::AddSimulateCommand(app);
  hw::cli::AddBoundsCommand(app);
  hw::cli::AddPopCommand(app);
  hw::cli::AddDiagnoseCommand(app);
  hw::cli::AddScenarioCommand(app);
  hw::cli::AddBrouriCommand(app);
  hw::cli::AddEsmaeilaniCommand(app);
  hw::cli::AddCompareCommand(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // --help exits 0; every other parse error is bad input, exit status 2 as for InputError.
    return app.exit(e) == 0 ? 0 : 2;
  } catch (const hw::cli::CommandExit& e) {
    return e.code;
  } catch (const hw::InputError& e) {
    fmt::print(stderr, "error: {}\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    fmt::print(stderr, "error: {}\n", e.what());
    return 1;
  }
  return 0;
}
