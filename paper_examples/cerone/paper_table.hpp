#pragma once
// The intervals printed in Tables I-III of paper 001 (Cerone, Piga, Regruto; relaxation order delta = 3), for the
// dynamic horizons n = 2 and n = 3.
#include <optional>
#include <string>

namespace hw::cerone {

struct PaperInterval {
  double lower = 0.0, upper = 0.0;
  double half_width() const { return 0.5 * (upper - lower); }
};

// The paper's interval of parameter `name` (hwbounds' names: gamma2, alpha3, a1, ...) at horizon n; none for a
// horizon or name the paper does not print.
std::optional<PaperInterval> PaperTableInterval(const std::string& name, int horizon);

}  // namespace hw::cerone
