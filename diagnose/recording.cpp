#include "diagnose/recording.hpp"

#include <cctype>
#include <cmath>
#include <fstream>
#include <sstream>
#include <tuple>

#include <fmt/format.h>

#include "core/csv_table.hpp"
#include "core/recording.hpp"

namespace hw::diagnose {
namespace {

std::string Trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t\r\"'");
  if (b == std::string::npos) return "";
  const auto e = s.find_last_not_of(" \t\r\"'");
  return s.substr(b, e - b + 1);
}

std::vector<std::string> SplitCells(const std::string& line) {
  std::vector<std::string> cells;
  std::string cell;
  std::istringstream in(line);
  while (std::getline(in, cell, ',')) cells.push_back(Trim(cell));
  if (!line.empty() && line.back() == ',') cells.emplace_back();
  return cells;
}

// Index of `name` in the header; -1 when absent; throws when it is there twice.
long FindColumn(const std::vector<std::string>& header, const std::string& name, const std::string& source) {
  long found = -1;
  for (std::size_t i = 0; i < header.size(); ++i)
    if (header[i] == name) {
      if (found >= 0)
        throw InputError(fmt::format("{}: column '{}' appears twice in the header (columns {} and {}); rename one",
                                     source, name, found + 1, i + 1));
      found = static_cast<long>(i);
    }
  return found;
}

std::string HeaderList(const std::vector<std::string>& header) {
  std::string s;
  for (const auto& h : header) s += (s.empty() ? "" : ", ") + (h.empty() ? std::string("(unnamed)") : "'" + h + "'");
  return s;
}

}  // namespace

RecordingSource RecordingSource::Parse(const std::string& text, const ColumnNames& defaults) {
  RecordingSource s;
  s.columns = defaults;
  s.path = text;
  if (text.empty()) throw InputError("recording '': no file name; expected FILE or FILE:u=NAME,y=NAME[,t=NAME]");
  const auto colon = text.rfind(':');
  if (colon == std::string::npos || text.find('=', colon) == std::string::npos) return s;
  s.path = text.substr(0, colon);
  std::istringstream in(text.substr(colon + 1));
  std::string item, keys;  // keys: those given so far (a column named twice would silently take the last)
  while (std::getline(in, item, ',')) {
    const auto eq = item.find('=');
    const std::string key = eq == std::string::npos ? item : item.substr(0, eq);
    const std::string value = eq == std::string::npos ? "" : item.substr(eq + 1);
    if (value.empty() || (key != "u" && key != "y" && key != "t"))
      throw InputError(fmt::format("recording '{}': '{}' not understood; expected FILE or FILE:u=NAME,y=NAME[,t=NAME]",
                                   text, item));
    if (keys.find(key) != std::string::npos)
      throw InputError(fmt::format("recording '{}': column '{}' is named twice; give each of u, y, t once", text, key));
    keys += key;
    if (key == "u") s.columns.u = value;
    if (key == "y") s.columns.y = value;
    if (key == "t") s.columns.t = value, s.columns.t_required = true;
  }
  if (s.path.empty()) throw InputError(fmt::format("recording '{}': no file name before ':'", text));
  return s;
}

Recording ParseRecording(const std::string& text, const std::string& source, const ColumnNames& c,
                         std::size_t min_samples) {
  std::istringstream in(text);
  std::string line;
  std::size_t line_no = 0;
  std::vector<std::string> header;
  while (header.empty() && std::getline(in, line)) {
    ++line_no;
    const std::string t = Trim(line);
    if (t.empty() || t[0] == '#') continue;
    header = SplitCells(line);
  }
  if (header.empty()) throw InputError(fmt::format("{}: empty file; expected a header line and data rows", source));
  const long iu = FindColumn(header, c.u, source), iy = FindColumn(header, c.y, source);
  const long it = FindColumn(header, c.t, source);
  for (const auto& [idx, name, role] : {std::tuple{iu, c.u, "input"}, std::tuple{iy, c.y, "output"}})
    if (idx < 0)
      throw InputError(fmt::format("{}: no {} column '{}'; the header has: {} (choose one with --u-col/--y-col or "
                                   "FILE:u=NAME,y=NAME)", source, role, name, HeaderList(header)));
  if (it < 0 && c.t_required)
    throw InputError(fmt::format("{}: no time column '{}'; the header has: {}", source, c.t, HeaderList(header)));
  Recording r;
  r.name = source;
  const std::vector<std::pair<long, std::vector<double>*>> used = {{iu, &r.u}, {iy, &r.y}, {it, &r.t}};
  while (std::getline(in, line)) {
    ++line_no;
    const std::string t = Trim(line);
    if (t.empty() || t[0] == '#') continue;
    const auto cells = SplitCells(line);
    for (const auto& [idx, dest] : used) {
      if (idx < 0) continue;
      const std::string& name = header[idx];
      if (static_cast<std::size_t>(idx) >= cells.size() || cells[idx].empty())
        throw InputError(fmt::format("{}:{}: column '{}' is empty; every row needs a number there", source, line_no,
                                     name));
      char* end = nullptr;
      const double v = std::strtod(cells[idx].c_str(), &end);
      if (end == cells[idx].c_str() || *end != '\0' || !std::isfinite(v))
        throw InputError(fmt::format("{}:{}: column '{}' holds '{}', which is not a finite number", source, line_no,
                                     name, cells[idx]));
      dest->push_back(v);
    }
  }
  if (it < 0) {
    r.t.resize(r.u.size());
    for (std::size_t i = 0; i < r.t.size(); ++i) r.t[i] = static_cast<double>(i);
  }
  CheckTimeColumn(r.t, source, fmt::format("column '{}'", c.t));  // core/recording.hpp: one message everywhere
  if (r.u.size() < min_samples)
    throw InputError(fmt::format("{}: {} samples; the diagnosis needs at least {}", source, r.u.size(), min_samples));
  return r;
}

Recording MakeRecording(std::string name, std::vector<double> t, std::vector<double> u, std::vector<double> y,
                        const std::string& t_col, std::size_t min_samples) {
  if (u.size() != y.size() || (!t.empty() && t.size() != u.size()))
    throw InputError(fmt::format("{}: u, y{} must have the same length (got {}, {}{})", name, t.empty() ? "" : " and t",
                                 u.size(), y.size(), t.empty() ? "" : fmt::format(", {}", t.size())));
  if (t.empty()) {
    t.resize(u.size());
    for (std::size_t i = 0; i < t.size(); ++i) t[i] = static_cast<double>(i);
  }
  CheckTimeColumn(t, name, fmt::format("column '{}'", t_col));
  if (u.size() < min_samples)
    throw InputError(fmt::format("{}: {} samples; the diagnosis needs at least {}", name, u.size(), min_samples));
  return {std::move(name), std::move(t), std::move(u), std::move(y)};
}

namespace {

bool IsMatPath(const std::string& path) {
  if (path.size() < 4) return false;
  std::string ext = path.substr(path.size() - 4);
  for (auto& ch : ext) ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
  return ext == ".mat";
}

// A MATLAB file through the project's reader (core/recording.hpp): the variables named by the spec
// become u, y (and t when named, or when the file has a variable t).
Recording ReadMatRecording(const RecordingSource& spec, std::size_t min_samples) {
  const ColumnNames& c = spec.columns;
  std::string map;  // only the columns whose variable is not named like the column itself
  for (const auto& [column, variable] : {std::pair<std::string, std::string>{"u", c.u}, {"y", c.y}, {"t", c.t}})
    if (variable != column && (column != "t" || c.t_required)) map += (map.empty() ? "" : ",") + column + "=" + variable;
  const std::string text = map.empty() ? spec.path : spec.path + ":" + map;
  const CsvTable tab = read_recording(text, {"u", "y"}, {"t"});
  Recording r = MakeRecording(spec.path, tab.has("t") ? tab.column("t") : std::vector<double>{}, tab.column("u"),
                              tab.column("y"), c.t, min_samples);
  return r;
}

}  // namespace

Recording ReadRecording(const RecordingSource& spec, std::size_t min_samples) {
  if (IsMatPath(spec.path)) return ReadMatRecording(spec, min_samples);
  std::ifstream in(spec.path);
  if (!in) throw InputError(fmt::format("{}: cannot open file", spec.path));
  std::stringstream ss;
  ss << in.rdbuf();
  return ParseRecording(ss.str(), spec.path, spec.columns, min_samples);
}

Recording Slice(const Recording& r, std::size_t from, std::size_t to, const std::string& name) {
  Recording s;
  s.name = name;
  to = std::min(to, r.u.size());
  from = std::min(from, to);
  s.t.assign(r.t.begin() + from, r.t.begin() + to);
  s.u.assign(r.u.begin() + from, r.u.begin() + to);
  s.y.assign(r.y.begin() + from, r.y.begin() + to);
  return s;
}

}  // namespace hw::diagnose
