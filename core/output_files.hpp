#pragma once
// Result files of a command: their paths are checked before any work, and they are written together at the
// end, only when the command succeeds. A path that cannot be written fails at once (not after an hour of
// solving), and a failure never leaves a half-written result or a stray .tmp file behind.
#include <string>
#include <utility>
#include <vector>

namespace hw {

// InputError unless `path` can be written as a file: it is not a directory and its parent directory exists
// and is writable. `option` names the command-line option in the message, e.g. "--json".
void CheckOutputFile(const std::string& path, const std::string& option);
// InputError unless `path` is a writable directory, or can be created as one (its nearest existing ancestor
// is a writable directory).
void CheckOutputDirectory(const std::string& path, const std::string& option);

// Whether gnuplot is on the PATH (figures are optional: without it, callers keep the data and scripts).
bool GnuplotAvailable();
// Whether that gnuplot has the output terminal `name` (e.g. "pngcairo").
bool GnuplotHasTerminal(const std::string& name);
// Runs `script` (a file name inside `dir`) with gnuplot in `dir`, its output to `script`.log there. Returns ""
// on success, otherwise a message naming the log.
std::string RunGnuplot(const std::string& dir, const std::string& script);

// Files written at the end of a command: each is staged to path.tmp, then all are renamed into place. A
// failure while staging removes every staged file, so either all results appear or none do.
class OutputFiles {
 public:
  void Add(std::string path, std::string text);
  void Commit();  // throws std::runtime_error naming the file that could not be written
  const std::vector<std::pair<std::string, std::string>>& files() const { return files_; }

 private:
  std::vector<std::pair<std::string, std::string>> files_;
};

}  // namespace hw
