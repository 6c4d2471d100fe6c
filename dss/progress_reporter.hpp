#pragma once
// Progress of a bounds run for a person: phases with jobs done / total and an ETA from the jobs done in the phase.
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <utility>

#include "dss/bounds_summary.hpp"

namespace hw::dss {

class ProgressReporter {
 public:
  ProgressReporter(std::function<void(const BoundsProgress&)> sink);
  void Phase(const std::string& name, int total);  // starts a phase
  void Done(int jobs = 1);
  // `jobs` of the phase come from the run cache: they leave the total, and their next Done() calls are not
  // counted, so done/total and the ETA measure the work still to run.
  void FromCache(int jobs);
  void Message(const std::string& text);            // a one-off line (e.g. resuming)
  // A job of the phase bounds `parameter` from below (dir -1) or above (+1) at `value`; call before its Done().
  void Bound(const std::string& parameter, int dir, double value);

 private:
  BoundsProgress Event() const;

  std::function<void(const BoundsProgress&)> sink_;
  std::string phase_;
  int done_ = 0, total_ = 0, from_cache_ = 0, uncounted_ = 0;
  double phase_start_ = 0.0;
  // The phase's interval so far per parameter (BoundsProgress::so_far_*), and the parameter bounded last.
  std::map<std::string, std::pair<std::optional<double>, std::optional<double>>> so_far_;
  std::string last_bounded_;
};

}  // namespace hw::dss
