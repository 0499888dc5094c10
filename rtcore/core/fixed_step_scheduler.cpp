// Absolute-deadline sleeping for the real-time scheduler.
#include "rtcore/core/fixed_step_scheduler.h"

#include <time.h>

#include <cerrno>

#include "rtcore/concurrency/spin_pause.h"

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

void FixedStepScheduler::wait_until(std::int64_t deadline_ns) {
  const std::int64_t now = FrameProfiler::now_ns();
  if (awake_since_ns_ < 0) awake_since_ns_ = now;
  const std::int64_t busy_ns = now - awake_since_ns_;
  const std::int64_t spin_ns = duty_.allowed_spin_ns(std::min(config_.spin_ns, deadline_ns - now), busy_ns);
  duty_.record(busy_ns);
  if (spin_ns <= 0) {
    sleep_until(deadline_ns);
    awake_since_ns_ = FrameProfiler::now_ns();
    if (wake_hook_ != nullptr) wake_hook_(wake_context_);
    return;
  }
  const std::int64_t spin_from_ns = deadline_ns - spin_ns;
  if (now < spin_from_ns) sleep_until(spin_from_ns);
  if (wake_hook_ != nullptr) wake_hook_(wake_context_);
  // The spin is running time: the next cycle counts it from here.
  awake_since_ns_ = FrameProfiler::now_ns();
  while (FrameProfiler::now_ns() < deadline_ns) spin_pause();
}

}  // namespace resecto
