#include "dss/job_outcome.hpp"

namespace hw::dss {

nlohmann::json JobOutcome::to_json() const {
  return {{"status", ToString(status)}, {"bound", bound}, {"tight", tight}, {"message", message}, {"rounds", rounds},
          {"sdp_iterations", sdp_iterations}, {"seconds", seconds}, {"moments", moments}, {"blocks", blocks},
          {"working_set", working_set}, {"active_set", active_set}, {"verification", sdp::ToString(verification)}, {"float_bound", float_bound},
          {"correction", correction}, {"verify_seconds", verify_seconds}, {"origin", ToString(origin)},
          {"bound_round", bound_round}, {"unfinished", unfinished},
          {"beyond_known_value", beyond_known_value}, {"first_moments", first_moments}};
}

JobOutcome JobOutcome::from_json(const nlohmann::json& j) {
  JobOutcome o;
  o.status = JobStatusFromString(j.at("status"));
  o.bound = j.at("bound");
  o.tight = j.at("tight");
  o.message = j.at("message");
  o.rounds = j.at("rounds");
  o.sdp_iterations = j.at("sdp_iterations");
  o.seconds = j.at("seconds");
  o.moments = j.at("moments");
  o.blocks = j.at("blocks");
  o.working_set = j.at("working_set").get<std::vector<int>>();
  if (j.contains("active_set")) o.active_set = j.at("active_set").get<std::vector<int>>();
  o.verification = VerifyStatusFromString(j.at("verification"));
  o.float_bound = j.at("float_bound");
  o.correction = j.at("correction");
  o.verify_seconds = j.at("verify_seconds");
  o.origin = JobOriginFromString(j.at("origin"));
  o.bound_round = j.at("bound_round");
  o.unfinished = j.at("unfinished");
  o.beyond_known_value = j.value("beyond_known_value", false);
  if (j.contains("first_moments")) o.first_moments = j.at("first_moments").get<std::vector<double>>();
  return o;
}

}  // namespace hw::dss
