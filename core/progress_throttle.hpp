#pragma once
// Which progress lines of a long run get printed: boundary lines (a phase's first or last) always, the others
// at most one per interval, so fast phases do not flood the terminal and slow ones are never silent for long.

#include <cmath>

namespace hw {

class ProgressThrottle {
 public:
  explicit ProgressThrottle(double interval_seconds) : interval_(interval_seconds) {}
  // True when a line at time `now` (seconds) is due; a due line starts the next interval.
  bool Due(double now, bool boundary = false) {
    if (!boundary && now < last_ + interval_) return false;
    last_ = now;
    return true;
  }
  // The next line is due whatever its time (a new phase whose clock starts again at 0).
  void Reset() { last_ = -INFINITY; }

 private:
  double interval_;
  double last_ = -INFINITY;
};

}  // namespace hw
