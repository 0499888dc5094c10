// How much of the last second a real-time thread spent running, so its spin-waits can stay inside the
// kernel's real-time bandwidth. Linux lets SCHED_FIFO threads run at most sched_rt_runtime_us of
// every sched_rt_period_us (950 ms of each second by default) and then stops them for the rest of the
// period: up to 50 ms, fifty ticks of a 960 Hz core at once. The core's tick work plus its spin before
// each deadline can come near that, so the spin gives way first: it is cut to what keeps the last
// second's running time under the limit, and the thread sleeps instead.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

namespace resecto {

class RealtimeDuty {
 public:
  /// `window_cycles` wait cycles make up the window (one second of ticks); `limit_ns` is the running
  /// time the window may hold; 0 or fewer: no limit.
  RealtimeDuty(std::size_t window_cycles, std::int64_t limit_ns);

  /// Records one cycle's running time (work and spin since the thread last woke), dropping the
  /// cycle that falls out of the window.
  void record(std::int64_t busy_ns);
  /// The longest spin (at most `wanted_ns`) that keeps the window's running time, with `busy_now_ns`
  /// already spent in the current cycle, within the limit.
  std::int64_t allowed_spin_ns(std::int64_t wanted_ns, std::int64_t busy_now_ns) const;
  /// Running time over the window's last cycles (the one about to drop out excluded).
  std::int64_t window_busy_ns() const { return sum_ns_ - (ring_.empty() ? 0 : ring_[next_]); }
  bool limited() const { return limit_ns_ > 0; }

 private:
  std::vector<std::int64_t> ring_;
  std::size_t next_ = 0;
  std::int64_t sum_ns_ = 0;
  std::int64_t limit_ns_;
};

/// The fraction of each period the kernel lets real-time threads run (sched_rt_runtime_us over
/// sched_rt_period_us), or nothing when unlimited (-1) or unreadable. Reads /proc: call at start.
std::optional<double> realtime_bandwidth_fraction();
/// SchedulerConfig::max_busy_fraction for a real-time core on this machine: 5% under the kernel's
/// real-time bandwidth, or 0 (no limit) where the kernel sets none.
double realtime_busy_limit();

}  // namespace resecto
