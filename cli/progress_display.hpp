#pragma once
// How `hwbounds bounds` shows a long run's progress to a person: on a terminal one line per phase, rewritten in
// place (jobs done/total, ETA) and left standing when the phase ends; elsewhere (a pipe, a log file) plain lines
// at a phase's end and, in between, from 1 min on whenever the phase's time has doubled since the last line (1, 2,
// 4, 8 min, ..., then every 10 min), so that a phase gives a handful of lines on a slow or busy machine as on a
// fast one; or nothing at all.
#include <cstdio>
#include <string>

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
  // A phase's first plain line comes after `first_line_seconds`; the gap to the next one is the time elapsed so
  // far, at most `longest_gap_seconds`.
  ProgressDisplay(ProgressMode mode, std::FILE* out, double first_line_seconds = 60.0, double longest_gap_seconds = 600.0);
  ~ProgressDisplay();
  ProgressDisplay(const ProgressDisplay&) = delete;
  ProgressDisplay& operator=(const ProgressDisplay&) = delete;

  void Show(const dss::BoundsProgress& p);
  // Ends a live line still open, so that what is printed next starts on a line of its own.
  void Finish();

 private:
  void ShowMessage(const std::string& text);
  void ShowLive(const dss::BoundsProgress& p, const std::string& line);
  bool PlainLineDue(const dss::BoundsProgress& p);

  ProgressMode mode_;
  std::FILE* out_;
  double first_line_seconds_, longest_gap_seconds_;
  std::string plain_phase_;  // the phase the next plain line is timed for (kPlain)
  double next_plain_line_ = 0.0;  // its elapsed time at which a line is due
  std::string live_phase_;  // the phase whose line is open (kLive); empty: none
};

// "[phase] 3/20 jobs (+2 from the run directory), elapsed 12 s, ETA 68 s, a1 in [0.816, 1.667] so far" (the last part
// when a relaxation job of the phase has bounded a parameter: its interval over the phase's finished jobs; "?" for a
// side not bounded yet).
std::string ProgressLine(const dss::BoundsProgress& p);

}  // namespace hw::cli
