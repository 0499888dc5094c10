// Latency histogram and clock-offset estimation for the link's statistics.
#include "device/link/link_statistics.h"

#include <algorithm>
#include <cmath>

namespace resecto {

double ClockOffsetEstimator::observe(std::int64_t host_time_ns, std::uint64_t device_time_us) {
  const std::int64_t difference_ns = host_time_ns - static_cast<std::int64_t>(device_time_us) * 1000;
  if (!started_) {
    started_ = true;
    offset_ns_ = difference_ns;
  } else {
    const double elapsed_ns = static_cast<double>(host_time_ns - last_host_ns_);
    const auto creep_ns = static_cast<std::int64_t>(std::max(0.0, elapsed_ns) * drift_ppm_ * 1e-6);
    offset_ns_ = std::min(difference_ns, offset_ns_ + creep_ns);
  }
  last_host_ns_ = host_time_ns;
  return static_cast<double>(difference_ns - offset_ns_) * 1e-3;
}

}  // namespace resecto
