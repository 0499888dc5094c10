// Steady and virtual host clocks for the device link.
#include "device/transport/host_clock.h"

#include <chrono>
#include <thread>

namespace resecto {

std::int64_t SteadyHostClock::now_ns() const {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

void SteadyHostClock::sleep_until_ns(std::int64_t deadline_ns) {
  const std::chrono::steady_clock::time_point deadline{std::chrono::nanoseconds(deadline_ns)};
  std::this_thread::sleep_until(deadline);
}

void VirtualHostClock::sleep_until_ns(std::int64_t deadline_ns) {
  std::int64_t current = now_ns_.load(std::memory_order_acquire);
  // Only ever forward: a racing advance past the deadline wins.
  while (current < deadline_ns &&
         !now_ns_.compare_exchange_weak(current, deadline_ns, std::memory_order_acq_rel)) {
  }
}

void VirtualHostClock::advance_ns(std::int64_t delta_ns) {
  if (delta_ns > 0) now_ns_.fetch_add(delta_ns, std::memory_order_acq_rel);
}

}  // namespace resecto
