#include "rtcore/core/realtime_duty.h"

#include <algorithm>
#include <fstream>

namespace resecto {

RealtimeDuty::RealtimeDuty(std::size_t window_cycles, std::int64_t limit_ns) : ring_(limit_ns > 0 ? window_cycles : 0, 0), limit_ns_(limit_ns) {}

void RealtimeDuty::record(std::int64_t busy_ns) {
  if (ring_.empty()) return;
  sum_ns_ += busy_ns - ring_[next_];
  ring_[next_] = busy_ns;
  next_ = next_ + 1 == ring_.size() ? 0 : next_ + 1;
}

std::int64_t RealtimeDuty::allowed_spin_ns(std::int64_t wanted_ns, std::int64_t busy_now_ns) const {
  if (!limited()) return wanted_ns;
  // The current cycle will replace the oldest one in the window.
  const std::int64_t room = limit_ns_ - window_busy_ns() - busy_now_ns;
  return std::clamp<std::int64_t>(room, 0, std::max<std::int64_t>(wanted_ns, 0));
}

std::optional<double> realtime_bandwidth_fraction() {
  std::ifstream runtime_file("/proc/sys/kernel/sched_rt_runtime_us"), period_file("/proc/sys/kernel/sched_rt_period_us");
  long long runtime_us = 0, period_us = 0;
  if (!(runtime_file >> runtime_us) || !(period_file >> period_us) || runtime_us < 0 || period_us <= 0) return std::nullopt;
  return static_cast<double>(runtime_us) / static_cast<double>(period_us);
}

double realtime_busy_limit() {
  const std::optional<double> fraction = realtime_bandwidth_fraction();
  return fraction ? std::max(0.0, *fraction - 0.05) : 0.0;
}

}  // namespace resecto
