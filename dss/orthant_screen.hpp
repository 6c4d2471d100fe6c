#pragma once
// Stage 1 of the bound engine: the LP screen of every sign orthant. Each orthant's data rows and sign
// constraints, with every monomial a variable in [-1, 1] (even ones >= 0), form one LP (pop/moment_lp.hpp);
// an infeasible LP, with its certificate verified, proves the orthant empty. One LP per orthant over all rows is
// far cheaper than reducing the rows of orthants that are empty anyway, so the screen runs before the reduction;
// the reduction would not change its verdict (a dropped row is implied in the LP too).
#include <optional>
#include <vector>

#include "dss/job_context.hpp"
#include "dss/job_dispatch.hpp"

namespace hw::dss {

struct ScreenOptions {
  bool enabled = true;
};

struct ScreenResult {
  std::vector<int> alive;                 // orthants not proven empty, ascending
  std::vector<std::optional<EmptinessCertificate>> certificates;  // per orthant: the LP certificate of an empty one
};

ScreenResult ScreenOrthants(const ScreenOptions& options, EngineContext& ctx);

// The screen's job kind: {"kind": "lp", "l"} -> {"empty", "status", "verification"}.
inline constexpr char kScreenJob[] = "lp";
nlohmann::json AnswerScreenJob(const JobContext& job, const nlohmann::json& spec);

}  // namespace hw::dss
