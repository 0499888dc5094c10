// SCHED_FIFO through pthreads; failure (EPERM without the capability) is an answer, not an error.
#include "rtcore/core/thread_priority.h"

#include <sched.h>

#include <algorithm>

namespace resecto {

bool raise_to_fifo(pthread_t thread, int priority) {
  sched_param parameters{};
  parameters.sched_priority = std::clamp(priority, sched_get_priority_min(SCHED_FIFO), sched_get_priority_max(SCHED_FIFO));
  return pthread_setschedparam(thread, SCHED_FIFO, &parameters) == 0;
}

void restore_normal_scheduling(pthread_t thread) {
  sched_param parameters{};
  parameters.sched_priority = 0;
  (void)pthread_setschedparam(thread, SCHED_OTHER, &parameters);
}

}  // namespace resecto
