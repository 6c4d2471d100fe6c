#include "core/json_input.hpp"

#include <fstream>

#include <fmt/format.h>

#include "core/csv_table.hpp"

namespace hw {

void CheckKeys(const nlohmann::json& j, const std::vector<std::string_view>& allowed, const std::string& where) {
  if (!j.is_object()) throw InputError(fmt::format("{}: expected a JSON object, got {}", where, j.type_name()));
  for (const auto& [key, value] : j.items()) {
    bool known = false;
    for (const auto a : allowed) known = known || key == a;
    if (!known) {
      std::string all;
      for (const auto a : allowed) all += fmt::format("{}{}", all.empty() ? "" : ", ", a);
      throw InputError(fmt::format("{}: unknown key '{}'; allowed keys: {}", where, key, all));
    }
  }
}

nlohmann::json ParseJsonText(const std::string& text, const std::string& source, const std::string& what) {
  try {
    return nlohmann::json::parse(text);
  } catch (const nlohmann::json::exception& e) {
    throw InputError(fmt::format("{}: not valid JSON ({}): {}", source, what, e.what()));
  }
}

nlohmann::json ReadJsonFile(const std::string& path, const std::string& what) {
  return ParseJsonText(read_text_file(path, what), path, what);
}

std::optional<nlohmann::json> ReadStoredJson(const std::string& path) {
  std::ifstream in(path);
  if (!in) return std::nullopt;
  try {
    return nlohmann::json::parse(in);
  } catch (...) {
    return std::nullopt;
  }
}

}  // namespace hw
