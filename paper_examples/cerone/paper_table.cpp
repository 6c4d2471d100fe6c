#include "paper_examples/cerone/paper_table.hpp"

#include <map>

namespace hw::cerone {

std::optional<PaperInterval> PaperTableInterval(const std::string& name, int horizon) {
  // parameter -> (n -> [lower, upper]), as printed (three decimals).
  static const std::map<std::string, std::map<int, PaperInterval>> kPaper = {
      {"gamma2", {{2, {0.273, 0.547}}, {3, {0.313, 0.476}}}},
      {"gamma3", {{2, {-0.234, -0.043}}, {3, {-0.124, -0.071}}}},
      {"alpha2", {{2, {0.523, 1.147}}, {3, {0.664, 0.931}}}},
      {"alpha3", {{2, {2.432, 3.839}}, {3, {2.914, 3.521}}}},
      {"a1", {{2, {1.556, 1.999}}, {3, {1.612, 1.934}}}},
      {"a2", {{2, {0.695, 0.999}}, {3, {0.785, 0.968}}}},
      {"b1", {{2, {1.138, 2.194}}, {3, {1.345, 1.877}}}},
      {"b2", {{2, {1.572, 2.718}}, {3, {1.875, 2.331}}}},
  };
  const auto by_name = kPaper.find(name);
  if (by_name == kPaper.end()) return std::nullopt;
  const auto row = by_name->second.find(horizon);
  if (row == by_name->second.end()) return std::nullopt;
  return row->second;
}

}  // namespace hw::cerone
