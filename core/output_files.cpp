#include "core/output_files.hpp"

#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <stdexcept>

#include <fmt/format.h>

#include "core/csv_table.hpp"

namespace hw {
namespace fs = std::filesystem;
namespace {

bool IsWritableDirectory(const fs::path& dir) {
  std::error_code ec;
  return fs::is_directory(dir, ec) && ::access(dir.c_str(), W_OK | X_OK) == 0;
}

fs::path ParentOf(const std::string& path) {
  const fs::path parent = fs::path(path).parent_path();
  return parent.empty() ? fs::path(".") : parent;
}

void Stage(const std::string& tmp, const std::string& text) {
  std::ofstream out(tmp, std::ios::binary);
  if (!out) throw std::runtime_error(fmt::format("{}: cannot write ({})", tmp, std::strerror(errno)));
  out << text;
  out.flush();
  if (!out) throw std::runtime_error(fmt::format("{}: write failed ({})", tmp, std::strerror(errno)));
}

}  // namespace

void CheckOutputFile(const std::string& path, const std::string& option) {
  if (path.empty()) throw InputError(fmt::format("{}: the output path is empty", option));
  std::error_code ec;
  if (fs::is_directory(path, ec))
    throw InputError(fmt::format("{} {}: is a directory; give a file name, e.g. {}/result.json", option, path, path));
  const fs::path parent = ParentOf(path);
  if (!fs::exists(parent, ec))
    throw InputError(fmt::format("{} {}: the directory {} does not exist; create it first", option, path, parent.string()));
  if (!IsWritableDirectory(parent))
    throw InputError(fmt::format("{} {}: {} is not a writable directory", option, path, parent.string()));
}

void CheckOutputDirectory(const std::string& path, const std::string& option) {
  if (path.empty()) throw InputError(fmt::format("{}: the output directory is empty", option));
  std::error_code ec;
  fs::path p = fs::absolute(path, ec);
  if (fs::exists(p, ec)) {
    if (!fs::is_directory(p, ec)) throw InputError(fmt::format("{} {}: exists and is not a directory", option, path));
    if (!IsWritableDirectory(p)) throw InputError(fmt::format("{} {}: the directory is not writable", option, path));
    return;
  }
  while (!p.empty() && p != p.root_path() && !fs::exists(p, ec)) p = p.parent_path();
  if (!IsWritableDirectory(p))
    throw InputError(fmt::format("{} {}: cannot be created ({} is not a writable directory)", option, path, p.string()));
}

void OutputFiles::Add(std::string path, std::string text) { files_.emplace_back(std::move(path), std::move(text)); }

void OutputFiles::Commit() {
  std::vector<std::string> staged;
  try {
    for (const auto& [path, text] : files_) {
      staged.push_back(path + ".tmp");
      Stage(staged.back(), text);
    }
    for (const auto& [path, text] : files_) fs::rename(path + ".tmp", path);
  } catch (const std::exception& e) {
    std::error_code ec;
    for (const auto& tmp : staged) fs::remove(tmp, ec);
    throw std::runtime_error(fmt::format("writing the results failed, nothing was written: {}", e.what()));
  }
}

bool GnuplotAvailable() { return std::system("command -v gnuplot > /dev/null 2>&1") == 0; }

bool GnuplotHasTerminal(const std::string& name) {
  return std::system(fmt::format("gnuplot -e 'set terminal {}' > /dev/null 2>&1", name).c_str()) == 0;
}

std::string RunGnuplot(const std::string& dir, const std::string& script) {
  const std::string cmd = fmt::format("cd '{}' && gnuplot '{}' > '{}.log' 2>&1", dir, script, script);
  if (std::system(cmd.c_str()) == 0) return "";
  return fmt::format("gnuplot failed on {}/{}: see {}/{}.log", dir, script, dir, script);
}

}  // namespace hw
