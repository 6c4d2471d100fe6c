#include "cli/progress_display.hpp"

#include <unistd.h>

#include <algorithm>
#include <optional>

#include <fmt/format.h>

namespace hw::cli {
namespace {

constexpr const char* kRewriteLine = "\r\033[K";  // back to the line's start, erase it

bool PhaseEnds(const dss::BoundsProgress& p) { return p.done >= p.total; }

std::string SoFarText(const dss::BoundsProgress& p) {
  if (p.so_far_parameter.empty()) return "";
  const auto side = [](const std::optional<double>& v) { return v ? fmt::format("{:.6g}", *v) : std::string("?"); };
  return fmt::format(", {} in [{}, {}] so far", p.so_far_parameter, side(p.so_far_lower), side(p.so_far_upper));
}

}  // namespace

ProgressMode ChooseProgressMode(std::FILE* out, bool quiet, bool verbose) {
  if (quiet) return ProgressMode::kSilent;
  if (verbose) return ProgressMode::kPlain;
  return ::isatty(::fileno(out)) ? ProgressMode::kLive : ProgressMode::kPlain;
}

std::string ProgressLine(const dss::BoundsProgress& p) {
  return fmt::format("[{}] {}/{} jobs{}, elapsed {:.0f} s, ETA {:.0f} s{}", p.phase, p.done, p.total,
                     p.from_cache > 0 ? fmt::format(" (+{} from the run directory)", p.from_cache) : std::string(),
                     p.elapsed_seconds, p.eta_seconds, SoFarText(p));
}

ProgressDisplay::ProgressDisplay(ProgressMode mode, std::FILE* out, double first_line_seconds,
                                 double longest_gap_seconds)
    : mode_(mode), out_(out), first_line_seconds_(first_line_seconds), longest_gap_seconds_(longest_gap_seconds) {}

ProgressDisplay::~ProgressDisplay() { Finish(); }

void ProgressDisplay::Show(const dss::BoundsProgress& p) {
  if (mode_ == ProgressMode::kSilent) return;
  if (p.total < 0) return ShowMessage(p.phase);
  const std::string line = ProgressLine(p);
  if (mode_ == ProgressMode::kLive) return ShowLive(p, line);
  if (!PlainLineDue(p)) return;
  fmt::print(out_, "{}\n", line);
  std::fflush(out_);
}

bool ProgressDisplay::PlainLineDue(const dss::BoundsProgress& p) {
  if (p.phase != plain_phase_ || p.done <= 0) {  // a phase starts: its clock is at 0
    plain_phase_ = p.phase;
    next_plain_line_ = first_line_seconds_;
  }
  if (PhaseEnds(p)) return true;
  if (p.done <= 0 || p.elapsed_seconds < next_plain_line_) return false;
  next_plain_line_ = p.elapsed_seconds + std::min(std::max(p.elapsed_seconds, first_line_seconds_), longest_gap_seconds_);
  return true;
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
