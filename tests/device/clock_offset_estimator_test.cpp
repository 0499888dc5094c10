// ClockOffsetEstimator: the offset between the board's and the host's clocks as the lower envelope
// of observed differences, following a drifting board clock, and latency measured above it.
#include <gtest/gtest.h>

#include "device/link/link_statistics.h"

namespace resecto {
namespace {

constexpr std::int64_t kOffsetNs = 5'000'000'000;  // host clock minus device clock

TEST(ClockOffsetEstimator, FastestReportSetsTheOffsetAndLatencyIsMeasuredAboveIt) {
  ClockOffsetEstimator estimator(0.0);
  // Reports every millisecond with one-way delays 300, 120, 500 and 120 us.
  const double delays_us[] = {300.0, 120.0, 500.0, 120.0};
  double latency[4];
  for (int k = 0; k < 4; ++k) {
    const std::uint64_t device_us = 1000u * static_cast<std::uint64_t>(k);
    latency[k] = estimator.observe(kOffsetNs + static_cast<std::int64_t>((device_us + delays_us[k]) * 1000), device_us);
  }
  EXPECT_EQ(latency[0], 0.0);  // the first report is its own reference
  EXPECT_EQ(estimator.offset_ns(), kOffsetNs + 120'000);
  EXPECT_DOUBLE_EQ(latency[2], 380.0);  // 500 us over the fastest delay seen so far (120 us)
  EXPECT_DOUBLE_EQ(latency[3], 0.0);
}

TEST(ClockOffsetEstimator, LatencyIsNeverNegative) {
  ClockOffsetEstimator estimator(0.0);
  for (int k = 0; k < 100; ++k) {
    const std::uint64_t device_us = 1000u * static_cast<std::uint64_t>(k);
    const std::int64_t jitter_ns = ((k * 7919) % 400) * 1000;  // 0..399 us
    EXPECT_GE(estimator.observe(kOffsetNs + static_cast<std::int64_t>(device_us) * 1000 + jitter_ns, device_us), 0.0);
  }
}

TEST(ClockOffsetEstimator, FollowsABoardClockThatRunsSlow) {
  // The board's clock loses 100 ppm: the difference host - device grows by 100 us a second. With a
  // constant true delay, the measured latency must stay near zero rather than climb.
  ClockOffsetEstimator estimator(200.0);
  double worst_us = 0.0;
  for (int k = 0; k <= 60'000; ++k) {  // 60 s of 1 kHz reports
    const std::int64_t host_ns = kOffsetNs + static_cast<std::int64_t>(k) * 1'000'000 + 150'000;
    const auto device_us = static_cast<std::uint64_t>(static_cast<double>(k) * 1000.0 * (1.0 - 100e-6));
    worst_us = std::max(worst_us, estimator.observe(host_ns, device_us));
  }
  EXPECT_LT(worst_us, 2.0) << "the offset must creep up with the slower board clock";
}

TEST(ClockOffsetEstimator, ResetStartsAfresh) {
  ClockOffsetEstimator estimator(0.0);
  (void)estimator.observe(kOffsetNs, 0);
  estimator.reset();
  EXPECT_EQ(estimator.observe(2 * kOffsetNs, 0), 0.0);
  EXPECT_EQ(estimator.offset_ns(), 2 * kOffsetNs);
}

}  // namespace
}  // namespace resecto
