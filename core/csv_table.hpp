#pragma once
// Numeric CSV tables with a header row: the project's recording format.
// Errors name the file, the line, what is wrong and what would be right.
#include <map>
#include <string>
#include <vector>

#include "core/input_error.hpp"

namespace hw {

struct CsvTable {
  std::string source;                      // file name, for messages
  std::vector<std::string> names;          // header, in file order
  std::vector<std::vector<double>> columns;
  std::vector<int> lines;                  // file line (1-based) of each data row, for messages; may be empty

  std::size_t rows() const { return columns.empty() ? 0 : columns.front().size(); }
  bool has(const std::string& name) const;
  // Throws InputError naming the available columns when `name` is absent.
  const std::vector<double>& column(const std::string& name) const;
  void add_column(const std::string& name, std::vector<double> values);
};

// Reads a comma-separated file whose first non-comment line is a header. Lines starting with '#'
// are comments. Every cell must be a finite number unless allow_nonfinite.
CsvTable read_csv(const std::string& path, bool allow_nonfinite = false);
CsvTable parse_csv(const std::string& text, const std::string& source, bool allow_nonfinite = false);

// The whole file as text. A missing path, a directory or an unreadable file is an InputError naming the
// file and what it should be (`what`, e.g. "CSV file").
std::string read_text_file(const std::string& path, const std::string& what = "file");

// Writes atomically (core/atomic_write.hpp), so a killed run leaves no half-written file.
void write_csv(const std::string& path, const CsvTable& table, int precision = 12);
std::string format_csv(const CsvTable& table, int precision = 12);  // the text write_csv writes

}  // namespace hw
