#include <fmt/format.h>

#include "core/recording.hpp"
#include "diagnose/diagnose.hpp"

namespace hw::diagnose {

Recording MakeRecording(std::string name, std::vector<double> t, std::vector<double> u, std::vector<double> y,
                        const std::string& t_col) {
  if (u.size() != y.size() || (!t.empty() && t.size() != u.size()))
    throw InputError(fmt::format("{}: u, y{} must have the same length (got {}, {}{})", name, t.empty() ? "" : " and t",
                                 u.size(), y.size(), t.empty() ? "" : fmt::format(", {}", t.size())));
  if (t.empty()) {
    t.resize(u.size());
    for (std::size_t i = 0; i < t.size(); ++i) t[i] = static_cast<double>(i);
  }
  for (std::size_t i = 1; i < t.size(); ++i)
    if (!(t[i] > t[i - 1]))
      throw InputError(fmt::format("{}: column '{}' must increase strictly (data row {}: {} after {})", name, t_col,
                                   i + 1, t[i], t[i - 1]));
  if (u.size() < 60) throw InputError(fmt::format("{}: {} samples; the diagnosis needs at least 60", name, u.size()));
  return {std::move(name), std::move(t), std::move(u), std::move(y)};
}

Recording LoadRecording(const std::string& spec, const std::string& u_col, const std::string& y_col,
                        const std::string& t_col) {
  const CsvTable tab = read_recording(spec, {u_col, y_col}, {t_col});
  return MakeRecording(spec, tab.has(t_col) ? tab.column(t_col) : std::vector<double>{}, tab.column(u_col),
                       tab.column(y_col), t_col);
}

}  // namespace hw::diagnose
