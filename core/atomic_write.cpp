#include "core/atomic_write.hpp"

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <stdexcept>

#include <fmt/format.h>

namespace hw {

void write_text_atomic(const std::string& path, const std::string& text) {
  const std::string tmp = path + ".tmp";
  std::error_code ec;
  try {
    {
      std::ofstream out(tmp, std::ios::binary);
      if (!out) throw std::runtime_error(fmt::format("{}: cannot write ({})", tmp, std::strerror(errno)));
      out << text;
      out.flush();
      if (!out) throw std::runtime_error(fmt::format("{}: write failed", tmp));
    }
    std::filesystem::rename(tmp, path);
  } catch (const std::exception& e) {
    std::filesystem::remove(tmp, ec);  // never leave a half-written file behind
    throw std::runtime_error(fmt::format("{}: not written: {}", path, e.what()));
  }
}

}  // namespace hw
