// Absolute-deadline sleeping for the real-time scheduler.
#include "rtcore/core/fixed_step_scheduler.h"

#include <time.h>

#include <cerrno>

namespace resecto {

void FixedStepScheduler::sleep_until(std::int64_t deadline_ns) {
  // CLOCK_MONOTONIC is steady_clock's clock on Linux; an absolute deadline does not drift when a
  // sleep is interrupted or a tick overruns.
  timespec when{};
  when.tv_sec = static_cast<time_t>(deadline_ns / 1'000'000'000);
  when.tv_nsec = static_cast<long>(deadline_ns % 1'000'000'000);
  while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &when, nullptr) == EINTR) {
  }
}

void FixedStepScheduler::wait_until(std::int64_t deadline_ns) const {
  if (config_.spin_ns <= 0) {
    sleep_until(deadline_ns);
    return;
  }
  const std::int64_t spin_from_ns = deadline_ns - config_.spin_ns;
  if (FrameProfiler::now_ns() < spin_from_ns) sleep_until(spin_from_ns);
  while (FrameProfiler::now_ns() < deadline_ns) {
#if defined(__x86_64__) || defined(__i386__)
    __builtin_ia32_pause();  // tells the core (and a hypervisor) this is a spin
#endif
  }
}

}  // namespace resecto
