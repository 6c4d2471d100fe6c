#pragma once
// How `hwbounds bounds` shows a long run's progress to a person: on a terminal one line per phase, rewritten in
// place (jobs done/total, ETA) and left standing when the phase ends; elsewhere (a pipe, a log file) plain lines
// at a phase's start and end and at most one per interval in between; or nothing at all.
#include <cstdio>
#include <string>

#include "core/progress_throttle.hpp"
#include "dss/set_membership.hpp"

namespace hw::cli {

enum class ProgressMode {
  kSilent,  // --quiet
  kLive,    // a terminal: one line per phase, updated in place
  kPlain,   // not a terminal (or --verbose, whose per-round lines would break a live line): throttled lines
};

// kLive when `out` is a terminal, else kPlain; kSilent when quiet; kPlain when verbose.
ProgressMode ChooseProgressMode(std::FILE* out, bool quiet, bool verbose);

class ProgressDisplay {
 public:
  // Plain lines come at most one per `plain_interval_seconds` within a phase (its first and last always).
  ProgressDisplay(ProgressMode mode, std::FILE* out, double plain_interval_seconds = 10.0);
  ~ProgressDisplay();
  ProgressDisplay(const ProgressDisplay&) = delete;
  ProgressDisplay& operator=(const ProgressDisplay&) = delete;

  void Show(const dss::BoundsProgress& p);
  // Ends a live line still open, so that what is printed next starts on a line of its own.
  void Finish();

 private:
  void ShowMessage(const std::string& text);
  void ShowLive(const dss::BoundsProgress& p, const std::string& line);

  ProgressMode mode_;
  std::FILE* out_;
  ProgressThrottle throttle_;
  std::string live_phase_;  // the phase whose line is open (kLive); empty: none
};

// "[phase] 3/20 jobs (+2 from the run directory), elapsed 12 s, ETA 68 s".
std::string ProgressLine(const dss::BoundsProgress& p);

}  // namespace hw::cli
