// SCHED_FIFO through pthreads; failure (EPERM without the capability) is an answer, not an error.
#include "rtcore/core/thread_priority.h"

#include <sched.h>

namespace resecto {

bool raise_to_fifo(pthread_t thread, int priority) {
  // Out of range is a caller's mistake to report, not to round to the nearest priority.
  if (priority < sched_get_priority_min(SCHED_FIFO) || priority > sched_get_priority_max(SCHED_FIFO)) return false;
  sched_param parameters{};
  parameters.sched_priority = priority;
  return pthread_setschedparam(thread, SCHED_FIFO, &parameters) == 0;
}

void restore_normal_scheduling(pthread_t thread) {
  sched_param parameters{};
  parameters.sched_priority = 0;
  (void)pthread_setschedparam(thread, SCHED_OTHER, &parameters);
}

int keep_core_apart(pthread_t core, std::span<const pthread_t> others) {
  // The processors this process may use (a cgroup or taskset may allow fewer than the machine has).
  cpu_set_t allowed;
  CPU_ZERO(&allowed);
  if (sched_getaffinity(0, sizeof allowed, &allowed) != 0 || CPU_COUNT(&allowed) < 2) return -1;
  int last = -1;
  for (int cpu = 0; cpu < CPU_SETSIZE; ++cpu) {
    if (CPU_ISSET(cpu, &allowed)) last = cpu;
  }
  cpu_set_t core_set, rest = allowed;
  CPU_ZERO(&core_set);
  CPU_SET(last, &core_set);
  CPU_CLR(last, &rest);
  if (pthread_setaffinity_np(core, sizeof core_set, &core_set) != 0) return -1;
  for (const pthread_t other : others) (void)pthread_setaffinity_np(other, sizeof rest, &rest);
  return last;
}

}  // namespace resecto
