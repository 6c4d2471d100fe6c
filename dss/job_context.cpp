#include "dss/job_context.hpp"

#include "dss/run_cache.hpp"

namespace hw::dss {

JobContext::JobContext(const EngineSettings& settings, const HwOuterSet& prior_set)
    : settings_(settings), prior_set_(prior_set) {}

const HwOuterSet& JobContext::set_in(const ParameterBox& box) const {
  if (box == prior_set_.box()) return prior_set_;
  std::lock_guard<std::mutex> lock(mutex_);
  auto& slot = sets_[BoxHash(box)];
  if (!slot) slot = std::make_unique<HwOuterSet>(prior_set_.WithBox(box));
  return *slot;
}

const std::vector<DataConstraint>& JobContext::rows_in(const ParameterBox& box, int l) const {
  const HwOuterSet& s = set_in(box);
  std::lock_guard<std::mutex> lock(mutex_);
  auto& r = rows_[{BoxHash(box), l}];
  if (r.empty()) r = s.data_constraints(l);
  return r;
}

}  // namespace hw::dss
