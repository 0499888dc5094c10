// FixedStepScheduler: runs the core's step at integer ticks. Real-time mode sleeps to absolute
// deadlines (start + k * period, never accumulated), counts every tick that finishes after its
// deadline and by how much, and catches up by running late ticks back to back, at most a bounded
// number, before it re-anchors the schedule. Batch mode runs the same step as fast as it can.
// The step never sees the clock: only which tick it is.
#pragma once

#include <algorithm>
#include <cstdint>

#include "rtcore/core/profiler.h"
#include "rtcore/core/realtime_duty.h"

namespace resecto {

/// How long a real-time run spins before each tick unless told otherwise (`resecto run --spin-us`).
inline constexpr std::int64_t kDefaultRealtimeSpinUs = 250;

struct SchedulerConfig {
  std::int64_t period_ns = 1'041'667;  ///< one tick (960 Hz by default)
  bool realtime = false;
  /// Ticks the schedule may fall behind before it gives up catching up and starts afresh.
  std::uint64_t max_catch_up_ticks = 8;
  /// The last part of each wait is spent spinning instead of sleeping: a sleeping thread's wake-up
  /// can come late by far more than a tick's slack (an idle virtual CPU halts, and the host wakes it
  /// when it pleases), a spinning one is already running. Costs that much CPU per tick.
  std::int64_t spin_ns = 0;
  /// The share of each second the thread may run, spins included, before its spins give way to
  /// sleep (RealtimeDuty); 0: no limit. A SCHED_FIFO core sets it a little under the kernel's
  /// real-time bandwidth (realtime_bandwidth_fraction()).
  double max_busy_fraction = 0.0;
};

/// How well the real-time schedule held.
struct DeadlineReport {
  std::uint64_t ticks = 0;
  std::uint64_t misses = 0;          ///< ticks that finished after their deadline
  std::uint64_t resynchronizations = 0;
  double max_late_us = 0.0;          ///< the worst miss
  TimingHistogram late_us;          ///< lateness of the missed ticks only
};

class FixedStepScheduler {
 public:
  explicit FixedStepScheduler(const SchedulerConfig& config)
      : config_(config),
        duty_(static_cast<std::size_t>(1'000'000'000 / std::max<std::int64_t>(config.period_ns, 1)) + 1,
              static_cast<std::int64_t>(config.max_busy_fraction * 1e9)) {}

  /// Runs `step(tick)` for ticks [first, first + count), in order; `step` returns false to stop early.
  template <class Step>
  void run(std::uint64_t first, std::uint64_t count, Step&& step) {
    std::int64_t anchor_ns = FrameProfiler::now_ns();
    std::uint64_t anchor_tick = first;
    for (std::uint64_t tick = first; tick < first + count; ++tick) {
      if (config_.realtime) {
        const std::int64_t start_ns = anchor_ns + static_cast<std::int64_t>(tick - anchor_tick) * config_.period_ns;
        const std::int64_t now = FrameProfiler::now_ns();
        if (now < start_ns) {
          wait_until(start_ns);
        } else if (now - start_ns > static_cast<std::int64_t>(config_.max_catch_up_ticks) * config_.period_ns) {
          // Too far behind to catch up without a burst: start the schedule afresh from here.
          anchor_ns = now;
          anchor_tick = tick;
          ++report_.resynchronizations;
        }
      }
      const bool go_on = step(tick);
      ++report_.ticks;
      if (config_.realtime) {
        const std::int64_t deadline_ns = anchor_ns + static_cast<std::int64_t>(tick + 1 - anchor_tick) * config_.period_ns;
        const std::int64_t late_ns = FrameProfiler::now_ns() - deadline_ns;
        if (late_ns > 0) {
          ++report_.misses;
          const double late_us = static_cast<double>(late_ns) * 1e-3;
          report_.late_us.add(late_us);
          if (late_us > report_.max_late_us) report_.max_late_us = late_us;
        }
      }
      if (!go_on) break;
    }
  }

  const DeadlineReport& report() const { return report_; }

  /// Real time: calls hook(context) each time the thread wakes for a tick, before its spin to the
  /// deadline (so about spin_ns ahead of the tick): time for another thread to be woken and be
  /// running when the tick begins.
  void set_wake_hook(void (*hook)(void*), void* context) {
    wake_hook_ = hook;
    wake_context_ = context;
  }

 private:
  static void sleep_until(std::int64_t deadline_ns);
  /// Sleeps until `spin_ns` (or what the duty allows of it) before the deadline, then spins to it.
  void wait_until(std::int64_t deadline_ns);

  SchedulerConfig config_;
  DeadlineReport report_;
  RealtimeDuty duty_;
  std::int64_t awake_since_ns_ = -1;  // when the thread last stopped sleeping
  void (*wake_hook_)(void*) = nullptr;
  void* wake_context_ = nullptr;
};

}  // namespace resecto
