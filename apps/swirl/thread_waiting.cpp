#include "thread_waiting.hpp"

#include <cstdlib>

#include <unistd.h>

namespace swirl::cli {

void adopt_thread_waiting(char** argv) {
  if (std::getenv("OMP_WAIT_POLICY") || std::getenv("GOMP_SPINCOUNT")) return;
  // Set before the exec, and left set if the exec fails: the next swirl this
  // process starts then does not try again.
  if (setenv("GOMP_SPINCOUNT", kSpinCount, 1) != 0) return;
  execv("/proc/self/exe", argv);
}

}  // namespace swirl::cli
