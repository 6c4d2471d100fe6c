#include "dss/job_function.hpp"

#include <map>
#include <memory>
#include <stdexcept>
#include <string>

#include "dss/edge_witness.hpp"
#include "dss/orthant_screen.hpp"
#include "dss/relax_job.hpp"
#include "dss/row_reduction.hpp"

namespace hw::dss {
namespace {

const std::map<std::string, JobHandler>& Handlers() {
  static const std::map<std::string, JobHandler> handlers{{kScreenJob, AnswerScreenJob},
                                                          {kReduceJob, AnswerReduceJob},
                                                          {kWitnessJob, AnswerWitnessJob},
                                                          {kRelaxJob, AnswerRelaxJob}};
  return handlers;
}

}  // namespace

sdp::JobFunction MakeJobFunction(const EngineSettings& settings, const HwOuterSet& set) {
  auto job = std::make_shared<JobContext>(settings, set);
  return [job](const std::string& text) -> std::string {
    const auto spec = nlohmann::json::parse(text);
    const std::string kind = spec.at("kind");
    const auto handler = Handlers().find(kind);
    if (handler == Handlers().end()) throw std::runtime_error("unknown job kind '" + kind + "'");
    return handler->second(*job, spec).dump();
  };
}

}  // namespace hw::dss
