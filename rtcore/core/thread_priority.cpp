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

}  // namespace resecto
