#include "core/worker_process.hpp"

#include <signal.h>
#include <sys/prctl.h>
#include <unistd.h>

namespace hw {

void EndWithParent(pid_t parent) {
  ::prctl(PR_SET_PDEATHSIG, SIGKILL);
  // The parent may have ended between fork() and prctl(): then the signal was never armed.
  if (::getppid() != parent) ::_exit(1);
}

}  // namespace hw
