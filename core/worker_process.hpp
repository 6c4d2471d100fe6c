#pragma once
// Forked worker processes that never outlive the process that forked them.
#include <sys/types.h>

namespace hw {

// Call first thing in a forked child, with the parent's pid taken before fork(). The kernel then sends the
// child SIGKILL when the parent ends, whatever ended it (SIGINT, SIGTERM, SIGKILL, a crash), so no worker is
// left running with PPID 1. A child whose parent is already gone exits at once.
void EndWithParent(pid_t parent);

}  // namespace hw
