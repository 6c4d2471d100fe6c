#include "dss/progress_reporter.hpp"

#include <algorithm>
#include <chrono>

namespace hw::dss {
namespace {

double now_seconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

}  // namespace

ProgressReporter::ProgressReporter(std::function<void(const BoundsProgress&)> sink) : sink_(std::move(sink)) {}

void ProgressReporter::Phase(const std::string& name, int total) {
  phase_ = name;
  done_ = 0;
  total_ = total;
  from_cache_ = uncounted_ = 0;
  phase_start_ = now_seconds();
  if (sink_ && total > 0) sink_({phase_, 0, total_, 0, 0.0, 0.0});
}

void ProgressReporter::FromCache(int jobs) {
  if (jobs <= 0) return;
  total_ = std::max(0, total_ - jobs);
  from_cache_ += jobs;
  uncounted_ += jobs;
  if (sink_) sink_({phase_, done_, total_, from_cache_, now_seconds() - phase_start_, 0.0});
}

void ProgressReporter::Done(int jobs) {
  const int skip = std::min(jobs, uncounted_);
  uncounted_ -= skip;
  jobs -= skip;
  if (jobs <= 0) return;
  done_ += jobs;
  if (!sink_) return;
  const double el = now_seconds() - phase_start_;
  sink_({phase_, done_, total_, from_cache_, el, done_ > 0 ? el / done_ * (total_ - done_) : 0.0});
}

void ProgressReporter::Message(const std::string& text) {
  if (sink_) sink_({text, -1, -1, 0, 0.0, 0.0});
}

}  // namespace hw::dss
