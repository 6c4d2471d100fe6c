#include "cli/progress_display.hpp"

#include <unistd.h>

#include <fmt/format.h>

namespace hw::cli {
namespace {

constexpr const char* kRewriteLine = "\r\033[K";  // back to the line's start, erase it

bool PhaseEnds(const dss::BoundsProgress& p) { return p.done >= p.total; }

}  // namespace

ProgressMode ChooseProgressMode(std::FILE* out, bool quiet, bool verbose) {
  if (quiet) return ProgressMode::kSilent;
  if (verbose) return ProgressMode::kPlain;
  return ::isatty(::fileno(out)) ? ProgressMode::kLive : ProgressMode::kPlain;
}

std::string ProgressLine(const dss::BoundsProgress& p) {
  return fmt::format("[{}] {}/{} jobs{}, elapsed {:.0f} s, ETA {:.0f} s", p.phase, p.done, p.total,
                     p.from_cache > 0 ? fmt::format(" (+{} from the run directory)", p.from_cache) : std::string(),
                     p.elapsed_seconds, p.eta_seconds);
}

ProgressDisplay::ProgressDisplay(ProgressMode mode, std::FILE* out, double plain_interval_seconds)
    : mode_(mode), out_(out), throttle_(plain_interval_seconds) {}

ProgressDisplay::~ProgressDisplay() { Finish(); }

void ProgressDisplay::Show(const dss::BoundsProgress& p) {
  if (mode_ == ProgressMode::kSilent) return;
  if (p.total < 0) return ShowMessage(p.phase);
  const std::string line = ProgressLine(p);
  if (mode_ == ProgressMode::kLive) return ShowLive(p, line);
  // Each phase's clock starts at 0, and its first line is a boundary, so the throttle needs no reset.
  if (!throttle_.Due(p.elapsed_seconds, p.done <= 0 || PhaseEnds(p))) return;
  fmt::print(out_, "{}\n", line);
  std::fflush(out_);
}

void ProgressDisplay::ShowLive(const dss::BoundsProgress& p, const std::string& line) {
  if (!live_phase_.empty() && live_phase_ != p.phase) fmt::print(out_, "\n");  // a phase left unfinished stays
  fmt::print(out_, "{}{}", kRewriteLine, line);
  live_phase_ = p.phase;
  if (PhaseEnds(p)) Finish();
  std::fflush(out_);
}

void ProgressDisplay::ShowMessage(const std::string& text) {
  if (!live_phase_.empty()) fmt::print(out_, "{}", kRewriteLine);  // the next update writes the phase's line again
  live_phase_.clear();
  fmt::print(out_, "{}\n", text);
  std::fflush(out_);
}

void ProgressDisplay::Finish() {
  if (live_phase_.empty()) return;
  fmt::print(out_, "\n");
  std::fflush(out_);
  live_phase_.clear();
}

}  // namespace hw::cli
