#include "dss/orthant_screen.hpp"

#include <fmt/format.h>

#include "pop/moment_lp.hpp"
#include "sdp/sdp_solver.hpp"

namespace hw::dss {

nlohmann::json AnswerScreenJob(const JobContext& job, const nlohmann::json& spec) {
  const int l = spec.at("l");
  const HwOuterSet& set = job.prior_set();
  const auto& gen_options = job.settings().generation;
  std::vector<Polynomial> cons = set.sign_constraints(l);
  for (const auto& d : job.rows_in(set.box(), l)) cons.push_back(d.g);
  // An LP: DSDP's LP cone is not used for the screen (its certificates are checked on CSDP's and SDPA's form).
  const std::string& backend = job.settings().backend(1);
  auto solver = sdp::MakeSolver(backend == "dsdp" ? "csdp" : backend);
  sdp::SdpOptions lp_options = gen_options.sdp;
  lp_options.keep_dual_matrix = false;
  sdp::VerifiedBound cert;
  const auto s = pop::ScreenWithLinearProgram(cons, set.num_vars(), lp_options, *solver,
                                              gen_options.verify.enabled ? &cert : nullptr);
  return {{"empty", s.status == sdp::SdpStatus::kInfeasible}, {"status", sdp::ToString(s.status)},
          {"verification", sdp::ToString(cert.status)}};
}

ScreenResult ScreenOrthants(const ScreenOptions& options, EngineContext& ctx) {
  const int L = ctx.set.num_orthants();
  ScreenResult out;
  out.certificates.assign(L, std::nullopt);
  if (options.enabled) {
    std::vector<std::pair<std::string, std::string>> jobs;
    for (int l = 0; l < L; ++l)
      jobs.push_back({nlohmann::json{{"kind", kScreenJob}, {"l", l}}.dump(), fmt::format("lp_l{}", l)});
    ctx.progress.Phase("LP screen of orthants", L);
    DispatchJobs(ctx, jobs, [&](std::size_t l, const nlohmann::json& answer, bool) {
      // A failed screen proves nothing: the orthant stays.
      if (!answer.contains("job_error") && answer.at("empty").get<bool>()) {
        const bool verified =
            VerifyStatusFromString(answer.value("verification", "off")) == sdp::VerifyStatus::kVerified;
        out.certificates[l] = EmptinessCertificate{CertificateKind::kLinearProgram, 0, false, verified};
      }
      ctx.progress.Done();
    });
  }
  for (int l = 0; l < L; ++l)
    if (!out.certificates[l]) out.alive.push_back(l);
  return out;
}

}  // namespace hw::dss
