#include "core/csv_table.hpp"

#include <cerrno>
#include <cmath>
#include <cstring>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <fmt/format.h>

#include "core/atomic_write.hpp"

namespace hw {
namespace {

std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t\r\"");
  if (b == std::string::npos) return "";
  const auto e = s.find_last_not_of(" \t\r\"");
  return s.substr(b, e - b + 1);
}

std::vector<std::string> split(const std::string& line) {
  std::vector<std::string> cells;
  std::string cell;
  std::istringstream in(line);
  while (std::getline(in, cell, ',')) cells.push_back(trim(cell));
  if (!line.empty() && line.back() == ',') cells.emplace_back();
  return cells;
}

}  // namespace

bool CsvTable::has(const std::string& name) const {
  for (const auto& n : names)
    if (n == name) return true;
  return false;
}

const std::vector<double>& CsvTable::column(const std::string& name) const {
  for (std::size_t i = 0; i < names.size(); ++i)
    if (names[i] == name) return columns[i];
  std::string available;
  for (const auto& n : names) available += (available.empty() ? "" : ", ") + n;
  throw InputError(fmt::format("{}: no column '{}'; the header has: {}", source, name, available));
}

void CsvTable::add_column(const std::string& name, std::vector<double> values) {
  if (!columns.empty() && values.size() != rows())
    throw std::invalid_argument("add_column: length differs from the table's");
  names.push_back(name);
  columns.push_back(std::move(values));
}

CsvTable parse_csv(const std::string& text, const std::string& source, bool allow_nonfinite) {
  CsvTable table;
  table.source = source;
  // A UTF-8 byte-order mark (spreadsheet exports) is not part of the first column's name.
  std::istringstream in(text.rfind("\xEF\xBB\xBF", 0) == 0 ? text.substr(3) : text);
  std::string line;
  int line_no = 0;
  bool have_header = false;
  while (std::getline(in, line)) {
    ++line_no;
    const std::string t = trim(line);
    if (t.empty() || t[0] == '#') continue;
    auto cells = split(t);
    if (!have_header) {
      table.names = cells;
      for (std::size_t i = 0; i < cells.size(); ++i) {
        if (cells[i].empty())
          throw InputError(fmt::format("{}:{}: header column {} has no name; expected a header such as 't,u,y'",
                                       source, line_no, i + 1));
        for (std::size_t k = 0; k < i; ++k)
          if (cells[k] == cells[i])
            throw InputError(fmt::format("{}:{}: the header names column '{}' twice (columns {} and {}); every "
                                         "column needs its own name",
                                         source, line_no, cells[i], k + 1, i + 1));
      }
      table.columns.assign(cells.size(), {});
      have_header = true;
      continue;
    }
    // With allow_nonfinite, missing trailing cells read as NaN (e.g. a column filled in the first row only);
    // otherwise a short row is an error that counts its cells.
    if (cells.size() > table.names.size() || (cells.size() < table.names.size() && !allow_nonfinite))
      throw InputError(fmt::format("{}:{}: {} cells but the header has {} columns ({})", source, line_no,
                                   cells.size(), table.names.size(), fmt::join(table.names, ", ")));
    for (std::size_t c = 0; c < table.names.size(); ++c) {
      double v = std::nan("");
      if (c < cells.size() && !cells[c].empty()) {
        char* end = nullptr;
        v = std::strtod(cells[c].c_str(), &end);
        // Decimal numbers only: strtod would also read hexadecimal ("0x10" as 16).
        if (end == cells[c].c_str() || *end != '\0' || cells[c].find_first_of("xXpP") != std::string::npos)
          throw InputError(fmt::format("{}:{}: column '{}' holds '{}', which is not a number", source,
                                       line_no, table.names[c], cells[c]));
      }
      if (!allow_nonfinite && !std::isfinite(v))
        throw InputError(fmt::format("{}:{}: column '{}' is {}; every cell must be a finite number", source,
                                     line_no, table.names[c],
                                     c < cells.size() && !cells[c].empty() ? cells[c] : "empty"));
      table.columns[c].push_back(v);
    }
    table.lines.push_back(line_no);
  }
  if (!have_header) throw InputError(fmt::format("{}: empty file; expected a header line and data rows", source));
  if (table.rows() == 0) throw InputError(fmt::format("{}: header but no data rows", source));
  return table;
}

std::string read_text_file(const std::string& path, const std::string& what) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const auto status = fs::status(path, ec);
  if (!fs::exists(status)) throw InputError(fmt::format("{}: no such file; expected a {}", path, what));
  if (fs::is_directory(status)) throw InputError(fmt::format("{}: is a directory; expected a {}", path, what));
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(fmt::format("{}: cannot open ({}); expected a readable {}", path, std::strerror(errno), what));
  std::stringstream ss;
  ss << in.rdbuf();
  if (in.bad()) throw InputError(fmt::format("{}: read error; expected a readable {}", path, what));
  return ss.str();
}

CsvTable read_csv(const std::string& path, bool allow_nonfinite) {
  return parse_csv(read_text_file(path, "CSV file"), path, allow_nonfinite);
}

std::string format_csv(const CsvTable& table, int precision) {
  std::string out;
  for (std::size_t c = 0; c < table.names.size(); ++c) out += (c ? "," : "") + table.names[c];
  out += '\n';
  for (std::size_t r = 0; r < table.rows(); ++r) {
    for (std::size_t c = 0; c < table.columns.size(); ++c)
      out += (c ? "," : "") + fmt::format("{:.{}g}", table.columns[c][r], precision);
    out += '\n';
  }
  return out;
}

void write_csv(const std::string& path, const CsvTable& table, int precision) {
  write_text_atomic(path, format_csv(table, precision));
}

}  // namespace hw
