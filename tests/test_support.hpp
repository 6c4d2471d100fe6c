#pragma once
// Small helpers shared by the input/output tests: the message an input error carries, and running the CLI.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <chrono>
#include <cstdio>
#include <string>

namespace hw::testing_support {

inline bool Has(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

// The message of the exception `f` throws; a test failure when it throws none.
template <class F>
std::string ErrorOf(F&& f) {
  try {
    f();
  } catch (const std::exception& e) {
    return e.what();
  }
  ADD_FAILURE() << "no error thrown";
  return "";
}

struct CliRun {
  int code = -1;       // exit status (-1: killed by a signal)
  std::string output;  // stdout and stderr
  double seconds = 0;
};

// Runs a shell command line, e.g. "PATH=/empty prog args 2>&1", and collects its standard output.
inline CliRun RunCommand(const std::string& command) {
  const auto t0 = std::chrono::steady_clock::now();
  CliRun r;
  FILE* p = ::popen(command.c_str(), "r");
  char buf[4096];
  std::size_t n;
  while ((n = std::fread(buf, 1, sizeof buf, p)) > 0) r.output.append(buf, n);
  const int status = ::pclose(p);
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return r;
}

#ifdef HW_CLI_PATH
inline CliRun RunCli(const std::string& args) { return RunCommand(std::string(HW_CLI_PATH) + " " + args + " 2>&1"); }
#endif

}  // namespace hw::testing_support
