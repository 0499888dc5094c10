// Latency histogram and clock-offset estimation for the link's statistics.
#include "device/link/link_statistics.h"

#include <algorithm>
#include <cmath>

namespace resecto {

void LatencyHistogram::add(double latency_us) {
  const double clamped = std::max(0.0, latency_us);
  const int bin = clamped >= kLatencyHistogramUs ? kLatencyHistogramUs : static_cast<int>(clamped);
  ++bins_[static_cast<std::size_t>(bin)];
  ++count_;
  max_us_ = std::max(max_us_, clamped);
}

double LatencyHistogram::quantile(double q) const {
  if (count_ == 0) return 0.0;
  // The rank of the q-quantile among count_ sorted values (nearest-rank definition).
  const auto rank = static_cast<std::uint64_t>(std::ceil(std::clamp(q, 0.0, 1.0) * static_cast<double>(count_)));
  const std::uint64_t target = std::max<std::uint64_t>(rank, 1);
  std::uint64_t seen = 0;
  for (int bin = 0; bin < kLatencyHistogramUs; ++bin) {
    seen += bins_[static_cast<std::size_t>(bin)];
    if (seen >= target) return std::min(bin + 0.5, max_us_);
  }
  return max_us_;
}

void LatencyHistogram::clear() {
  std::fill(bins_.begin(), bins_.end(), 0u);
  count_ = 0;
  max_us_ = 0.0;
}

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
