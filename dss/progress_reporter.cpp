#include "dss/progress_reporter.hpp"

#include <algorithm>
#include <chrono>
#include <tuple>

namespace hw::dss {
namespace {

double now_seconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

}  // namespace

ProgressReporter::ProgressReporter(std::function<void(const BoundsProgress&)> sink) : sink_(std::move(sink)) {}

BoundsProgress ProgressReporter::Event() const {
  const double elapsed = now_seconds() - phase_start_;
  BoundsProgress p{phase_, done_, total_, from_cache_, elapsed, done_ > 0 ? elapsed / done_ * (total_ - done_) : 0.0};
  if (const auto it = so_far_.find(last_bounded_); it != so_far_.end()) {
    p.so_far_parameter = last_bounded_;
    std::tie(p.so_far_lower, p.so_far_upper) = it->second;
  }
  return p;
}

void ProgressReporter::Phase(const std::string& name, int total) {
  phase_ = name;
  done_ = 0;
  total_ = total;
  from_cache_ = uncounted_ = 0;
  phase_start_ = now_seconds();
  so_far_.clear();
  last_bounded_.clear();
  if (!sink_ || total <= 0) return;
  BoundsProgress p = Event();
  p.elapsed_seconds = 0.0;
  sink_(p);
}

void ProgressReporter::FromCache(int jobs) {
  if (jobs <= 0) return;
  total_ = std::max(0, total_ - jobs);
  from_cache_ += jobs;
  uncounted_ += jobs;
  if (!sink_) return;
  BoundsProgress p = Event();
  p.eta_seconds = 0.0;
  sink_(p);
}

void ProgressReporter::Done(int jobs) {
  const int skip = std::min(jobs, uncounted_);
  uncounted_ -= skip;
  jobs -= skip;
  if (jobs <= 0) return;
  done_ += jobs;
  if (sink_) sink_(Event());
}

void ProgressReporter::Bound(const std::string& parameter, int dir, double value) {
  auto& [lower, upper] = so_far_[parameter];
  if (dir < 0) lower = std::min(lower.value_or(value), value);
  else upper = std::max(upper.value_or(value), value);
  last_bounded_ = parameter;
}

void ProgressReporter::Message(const std::string& text) {
  if (sink_) sink_({text, -1, -1, 0, 0.0, 0.0});
}

}  // namespace hw::dss
