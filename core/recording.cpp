#include "core/recording.hpp"

#include <algorithm>
#include <cctype>

#include <fmt/format.h>

namespace hw {
namespace {

std::string Lower(std::string s) {
  for (auto& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

std::string Trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t");
  if (b == std::string::npos) return "";
  return s.substr(b, s.find_last_not_of(" \t") - b + 1);
}

bool EndsWith(const std::string& s, const std::string& tail) {
  return s.size() >= tail.size() && s.compare(s.size() - tail.size(), tail.size(), tail) == 0;
}

constexpr const char* kMapSyntax = "expected FILE.mat:COLUMN=VARIABLE[,COLUMN=VARIABLE...], e.g. rec.mat:u=vir,y=qm";

std::vector<MatColumn> ParseMap(const std::string& text, const std::string& spec) {
  if (Trim(text).empty()) throw InputError(fmt::format("'{}': nothing after ':'; {}", spec, kMapSyntax));
  std::vector<MatColumn> map;
  std::size_t pos = 0;
  while (pos <= text.size()) {
    const auto comma = std::min(text.find(',', pos), text.size());
    const std::string item = text.substr(pos, comma - pos);
    const auto eq = item.find('=');
    MatColumn c;
    if (eq != std::string::npos) c = {Trim(item.substr(0, eq)), Trim(item.substr(eq + 1))};
    if (c.column.empty() || c.variable.empty())
      throw InputError(fmt::format("'{}': '{}' is not COLUMN=VARIABLE; {}", spec, item, kMapSyntax));
    for (const auto& m : map)
      if (m.column == c.column) throw InputError(fmt::format("'{}': column '{}' is mapped twice", spec, c.column));
    map.push_back(c);
    pos = comma + 1;
  }
  return map;
}

const MatColumn* Find(const std::vector<MatColumn>& map, const std::string& column) {
  for (const auto& m : map)
    if (m.column == column) return &m;
  return nullptr;
}

CsvTable ReadMat(const RecordingSpec& spec, const std::vector<std::string>& required,
                 const std::vector<std::string>& optional) {
  std::vector<std::string> names;  // the file's variables, read only when a column is not mapped
  bool have_names = false;
  std::vector<MatColumn> columns;
  auto add = [&](const std::string& column, bool is_required) {
    if (Find(columns, column)) return;
    if (const auto* m = Find(spec.map, column)) {
      columns.push_back(*m);
      return;
    }
    if (!have_names) names = mat_variable_names(spec.path), have_names = true;
    if (std::find(names.begin(), names.end(), column) != names.end()) {
      columns.push_back({column, column});
    } else if (is_required) {
      throw InputError(
          fmt::format("{}: no variable '{}' for the column {}; name its variable as {}:{}=VARIABLE "
                      "(the file has: {})",
                      spec.path, column, column, spec.path, column,
                      names.empty() ? "no variables" : fmt::format("{}", fmt::join(names, ", "))));
    }
  };
  for (const auto& c : required) add(c, true);
  for (const auto& c : optional) add(c, false);
  return read_mat_columns(spec.path, columns);
}

CsvTable ReadCsv(const RecordingSpec& spec, const std::vector<std::string>& required) {
  CsvTable table = read_csv(spec.path);
  std::vector<std::vector<double>> mapped;  // every source column is read before any is replaced (u=y,y=u)
  for (const auto& m : spec.map) mapped.push_back(table.column(m.variable));
  for (std::size_t i = 0; i < spec.map.size(); ++i) {
    const auto at = std::find(table.names.begin(), table.names.end(), spec.map[i].column);
    if (at != table.names.end())
      table.columns[at - table.names.begin()] = std::move(mapped[i]);
    else
      table.add_column(spec.map[i].column, std::move(mapped[i]));
  }
  for (const auto& c : required) table.column(c);  // throws naming the header when absent
  return table;
}

// The variable (.mat) or source column (CSV) that holds the column `column` of a recording.
std::string SourceOf(const RecordingSpec& spec, const std::string& column) {
  const auto* m = Find(spec.map, column);
  return fmt::format("{} '{}'", spec.mat ? "variable" : "column", m ? m->variable : column);
}

}  // namespace

void CheckTimeColumn(const std::vector<double>& t, const std::string& source, const std::string& what,
                     const std::vector<int>& lines) {
  for (std::size_t i = 1; i < t.size(); ++i) {
    if (t[i] > t[i - 1]) continue;
    const std::string where = i < lines.size() ? fmt::format("{}:{}: {}", source, lines[i], what)
                                               : fmt::format("{}: {} sample {}", source, what, i + 1);
    throw InputError(fmt::format("{} is {} after {}; the time t of a recording must increase strictly from sample "
                                 "to sample",
                                 where, t[i], t[i - 1]));
  }
}

std::string DescribeColumns(const std::vector<std::string>& required, const std::vector<std::string>& optional) {
  std::string s = fmt::format("{}", fmt::join(required, ", "));
  if (!optional.empty()) s += fmt::format("{}optionally {}", s.empty() ? "" : " and ", fmt::join(optional, ", "));
  return s;
}

RecordingSpec RecordingSpec::Parse(const std::string& text) {
  RecordingSpec spec;
  const std::string lower = Lower(text);
  const auto mat = lower.rfind(".mat:"), csv = lower.rfind(".csv:");
  const auto split = mat == std::string::npos ? csv : csv == std::string::npos ? mat : std::max(mat, csv);
  if (split == std::string::npos) {
    spec.path = text;
  } else {
    spec.path = text.substr(0, split + 4);
    spec.map = ParseMap(text.substr(split + 5), text);
  }
  spec.mat = EndsWith(Lower(spec.path), ".mat");
  return spec;
}

CsvTable read_recording(const std::string& text, const std::vector<std::string>& required,
                        const std::vector<std::string>& optional) {
  const RecordingSpec spec = RecordingSpec::Parse(text);
  for (const auto& m : spec.map)
    if (std::find(required.begin(), required.end(), m.column) == required.end() &&
        std::find(optional.begin(), optional.end(), m.column) == optional.end())
      throw InputError(fmt::format("'{}': unknown column '{}'; this command reads {}", text, m.column,
                                   DescribeColumns(required, optional)));
  CsvTable table = spec.mat ? ReadMat(spec, required, optional) : ReadCsv(spec, required);
  const bool reads_t = std::find(required.begin(), required.end(), "t") != required.end() ||
                       std::find(optional.begin(), optional.end(), "t") != optional.end();
  if (reads_t && table.has("t")) CheckTimeColumn(table.column("t"), spec.path, SourceOf(spec, "t"), table.lines);
  return table;
}

}  // namespace hw
