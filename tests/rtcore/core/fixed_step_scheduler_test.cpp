// The fixed-step scheduler: every tick in order, real time kept by absolute deadlines, overruns
// counted, and a schedule too far behind re-anchored rather than bursting.
#include <gtest/gtest.h>

#include <chrono>
#include <thread>
#include <vector>

#include "rtcore/core/fixed_step_scheduler.h"

namespace resecto {
namespace {

TEST(FixedStepScheduler, BatchRunsEveryTickInOrderAndStopsOnRequest) {
  FixedStepScheduler scheduler({});
  std::vector<std::uint64_t> seen;
  scheduler.run(5, 10, [&](std::uint64_t tick) {
    seen.push_back(tick);
    return tick < 11;
  });
  ASSERT_EQ(seen.size(), 7u);
  for (std::size_t i = 0; i < seen.size(); ++i) EXPECT_EQ(seen[i], 5 + i);
  EXPECT_EQ(scheduler.report().misses, 0u);
}

TEST(FixedStepScheduler, RealTimeTakesTheScheduledTimeAndCountsAnOverrun) {
  SchedulerConfig config;
  config.realtime = true;
  config.period_ns = 2'000'000;  // 500 Hz
  FixedStepScheduler scheduler(config);
  const auto start = std::chrono::steady_clock::now();
  scheduler.run(0, 100, [&](std::uint64_t tick) {
    if (tick == 40) std::this_thread::sleep_for(std::chrono::milliseconds(5));  // an overrun of ~3 ms
    return true;
  });
  const double elapsed_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  EXPECT_GE(elapsed_ms, 99 * 2.0);  // the last tick starts at 198 ms: the schedule is not run early
  EXPECT_EQ(scheduler.report().ticks, 100u);
  EXPECT_GE(scheduler.report().misses, 1u);
  EXPECT_GE(scheduler.report().max_late_us, 2000.0);
}

/// Real time at 1 ms ticks, the last 300 us before each spun.
SchedulerConfig spinning_schedule() {
  SchedulerConfig config;
  config.realtime = true;
  config.period_ns = 1'000'000;
  config.spin_ns = 300'000;
  return config;
}

TEST(FixedStepScheduler, SpinningTheLastStretchNeverStartsATickEarly) {
  FixedStepScheduler scheduler(spinning_schedule());
  std::vector<std::int64_t> starts;
  starts.reserve(50);
  scheduler.run(0, 50, [&](std::uint64_t) {
    starts.push_back(FrameProfiler::now_ns());
    return true;
  });
  ASSERT_EQ(starts.size(), 50u);
  // Tick 0 starts at the anchor (within the few microseconds before the first clock read).
  for (std::size_t k = 1; k < starts.size(); ++k) EXPECT_GE(starts[k] - starts[0], static_cast<std::int64_t>(k) * 1'000'000 - 20'000) << k;
}

TEST(FixedStepScheduler, TheWakeHookRunsOnceBeforeEachWaitedTickAndAheadOfIt) {
  // The hook runs while the scheduler waits for a tick, once, between the tick before and this one.
  // A tick the thread reached late (a loaded machine, a descheduled test) starts at once, with no
  // wait and no hook, so how many ticks had one depends on the machine.
  struct Wakes {
    std::vector<std::int64_t> at;
    std::vector<std::size_t> before_tick;
    const std::vector<std::int64_t>* starts;
  };
  FixedStepScheduler scheduler(spinning_schedule());
  std::vector<std::int64_t> starts;
  starts.reserve(50);
  Wakes wakes{{}, {}, &starts};
  wakes.at.reserve(50);
  wakes.before_tick.reserve(50);
  scheduler.set_wake_hook(
      [](void* out) {
        auto* w = static_cast<Wakes*>(out);
        w->at.push_back(FrameProfiler::now_ns());
        w->before_tick.push_back(w->starts->size());
      },
      &wakes);
  scheduler.run(0, 50, [&](std::uint64_t) {
    starts.push_back(FrameProfiler::now_ns());
    return true;
  });
  ASSERT_EQ(starts.size(), 50u);
  ASSERT_FALSE(wakes.at.empty());
  std::vector<bool> woken(starts.size(), false);
  for (std::size_t w = 0; w < wakes.at.size(); ++w) {
    const std::size_t k = wakes.before_tick[w];
    ASSERT_GE(k, 1u) << "tick 0 starts at once";
    ASSERT_LT(k, starts.size());
    EXPECT_FALSE(woken[k]) << "twice before tick " << k;
    woken[k] = true;
    EXPECT_GT(wakes.at[w], starts[k - 1]) << k;
    EXPECT_LE(wakes.at[w], starts[k]) << k;
  }
}

TEST(FixedStepScheduler, FarBehindReanchorsInsteadOfBursting) {
  SchedulerConfig config;
  config.realtime = true;
  config.period_ns = 1'000'000;
  config.max_catch_up_ticks = 4;
  FixedStepScheduler scheduler(config);
  scheduler.run(0, 30, [&](std::uint64_t tick) {
    if (tick == 10) std::this_thread::sleep_for(std::chrono::milliseconds(20));
    return true;
  });
  EXPECT_GE(scheduler.report().resynchronizations, 1u);  // a loaded machine may add more
  EXPECT_GE(scheduler.report().misses, 1u);
}

}  // namespace
}  // namespace resecto
