// LinkStatistics: what the link thread counts about the report stream — rate, loss, duplicates,
// reordering, rejections by reason, device-time jumps, disconnections — and the device-to-host latency
// after estimating the offset between the two clocks (the latency itself goes into the project's
// TimingHistogram). Fixed-size, so updating it per report allocates nothing.
#pragma once

#include <array>
#include <cstdint>

#include "device/link/board_flags.h"
#include "device/link/report_decoder.h"

namespace resecto {

/// Counters and summaries; a plain value, copied out as a snapshot.
struct LinkCounters {
  std::uint64_t reports = 0;            ///< raw reports read from the transport (valid or not)
  std::uint64_t accepted = 0;           ///< delivered toward the core (in-order samples)
  /// Sequence numbers never received intact: dropped in transit, or arrived corrupt (and so also
  /// counted in `rejected`). Late arrivals are refunded. Gaps across a disconnection are not loss.
  std::uint64_t lost = 0;
  std::uint64_t duplicates = 0;
  std::uint64_t out_of_order = 0;       ///< valid reports that arrived after a newer one (not delivered)
  std::uint64_t rejected = 0;           ///< sum over reasons
  std::array<std::uint64_t, kRejectReasonCount> rejected_by_reason{};  ///< indexed by RejectReason
  std::uint64_t device_time_jumps = 0;  ///< device time moved other than one period per sequence step
  std::uint64_t sequence_restarts = 0;  ///< the board's count started again (reboot)
  std::uint64_t missed_while_disconnected = 0;  ///< sequence numbers that went by while unplugged
  std::uint64_t ring_full = 0;          ///< samples the core's ring had no room for
  std::uint64_t connects = 0;
  std::uint64_t disconnects = 0;
  std::uint64_t silence_timeouts = 0;   ///< of the disconnects, those caused by silence
  std::uint64_t failed_opens = 0;
  BoardFlagCounts board_flags;          ///< the board's fault flags over the accepted reports
  double rate_hz = 0.0;                 ///< accepted samples per second while connected (host time)
  double latency_median_us = 0.0;       ///< device->host, above the estimated clock offset
  double latency_p99_us = 0.0;
  double latency_max_us = 0.0;
  bool connected = false;
};

/// Estimates host_time - device_time as the lower envelope of observed differences (the fastest
/// report bounds the offset), letting it creep up by `drift_ppm` to follow a slower board clock.
/// Latency is then measured relative to the fastest report: the one-way delay's variable part.
class ClockOffsetEstimator {
 public:
  explicit ClockOffsetEstimator(double drift_ppm = 200.0) : drift_ppm_(drift_ppm) {}
  /// Feeds one report; returns its latency in microseconds (>= 0).
  double observe(std::int64_t host_time_ns, std::uint64_t device_time_us);
  void reset() { started_ = false; }
  std::int64_t offset_ns() const { return offset_ns_; }

 private:
  double drift_ppm_;
  bool started_ = false;
  std::int64_t offset_ns_ = 0;
  std::int64_t last_host_ns_ = 0;
};

}  // namespace resecto
