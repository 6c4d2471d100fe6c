#include "dss/orthant_screen.hpp"

#include <fmt/format.h>

namespace hw::dss {

ScreenResult ScreenOrthants(const ScreenOptions& options, EngineContext& ctx) {
  const int L = ctx.set.num_orthants();
  ScreenResult out;
  out.status.assign(L, "undecided");
  out.certificates.assign(L, std::nullopt);
  if (options.enabled) {
    std::vector<std::pair<std::string, std::string>> jobs;
    for (int l = 0; l < L; ++l)
      jobs.push_back({nlohmann::json{{"kind", "lp"}, {"l", l}}.dump(), fmt::format("lp_l{}", l)});
    ctx.progress.Phase("LP screen of orthants", L);
    DispatchJobs(ctx, jobs, [&](std::size_t l, const nlohmann::json& answer, bool) {
      // A failed screen proves nothing: the orthant stays.
      if (!answer.contains("job_error") && answer.at("empty").get<bool>()) {
        const EmptinessCertificate lp{"lp", 0, false, answer.value("verification", "off") == "verified"};
        out.status[l] = lp.status();
        out.certificates[l] = lp;
      }
      ctx.progress.Done();
    });
  }
  for (int l = 0; l < L; ++l)
    if (out.status[l] == "undecided") out.alive.push_back(l);
  return out;
}

}  // namespace hw::dss
