// The machine's own floor for real-time deadlines: the core's FixedStepScheduler at the real-time
// run's settings (the default tick rate, the core's FIFO priority, the default spin), running ticks that
// only burn a fixed time on the CPU: no simulation, no memory traffic, no other thread. Whatever it
// misses, the machine missed: on a virtual machine the host takes the vCPU away for milliseconds now
// and then, and a tick caught in that is late whatever it computes, with the ticks that catch up after
// it. Printed beside what `resecto run --realtime` reports, it says how much of that figure the
// simulator could still remove. Args: busy time per tick (us), seconds.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <string>

#include "rtcore/core/fixed_step_scheduler.h"
#include "rtcore/core/simulation.h"
#include "rtcore/core/thread_priority.h"

namespace resecto {
namespace {

struct Floor {
  std::uint64_t ticks = 0, misses = 0, resynchronizations = 0;
  double worst_late_us = 0.0;
  bool fifo = false;
  double missed_percent() const { return 100.0 * static_cast<double>(misses) / static_cast<double>(std::max<std::uint64_t>(ticks, 1)); }
};
std::map<std::pair<std::int64_t, std::int64_t>, Floor>& floors() {
  static std::map<std::pair<std::int64_t, std::int64_t>, Floor> f;
  return f;
}

void burn_until(std::int64_t until_ns) {
  while (FrameProfiler::now_ns() < until_ns) {
  }
}

void BM_DeadlineFloor(benchmark::State& state) {
  const std::int64_t busy_us = state.range(0), seconds = state.range(1);
  Floor& floor = floors()[{busy_us, seconds}];
  // The default rates, rounded to a period as the headless runner rounds them.
  const double tick_s = SimulationConfig{}.tick_s();
  for (auto _ : state) {
    SchedulerConfig config;
    config.period_ns = static_cast<std::int64_t>(std::llround(tick_s * 1e9));
    config.realtime = true;
    config.spin_ns = kDefaultRealtimeSpinUs * 1000;
    FixedStepScheduler scheduler(config);
    const ScopedFifoPriority priority(kCoreFifoPriority);
    const auto ticks = static_cast<std::uint64_t>(std::llround(static_cast<double>(seconds) / tick_s));
    scheduler.run(0, ticks, [&](std::uint64_t) {
      burn_until(FrameProfiler::now_ns() + busy_us * 1000);
      return true;
    });
    const DeadlineReport& report = scheduler.report();
    floor = {report.ticks, report.misses, report.resynchronizations, report.max_late_us, priority.raised()};
  }
  state.counters["misses"] = static_cast<double>(floor.misses);
  state.counters["miss_percent"] = floor.missed_percent();
  state.counters["worst_late_us"] = floor.worst_late_us;
  state.counters["sched_fifo"] = floor.fifo ? 1 : 0;
}
// 300 us: the 8640-triangle model's physics step (tissue_bench, 2026-11-23); 0: the schedule alone.
BENCHMARK(BM_DeadlineFloor)->Args({300, 10})->Args({0, 10})->Iterations(1)->UseRealTime()->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace resecto

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  std::printf("\n%10s %8s | %8s %8s %10s %12s %12s | %s\n", "busy us", "seconds", "ticks", "misses", "missed %", "worst late us",
              "re-anchored", "scheduling");
  for (const auto& [key, floor] : resecto::floors()) {
    std::printf("%10lld %8lld | %8llu %8llu %9.3f%% %12.0f %12llu | %s\n", static_cast<long long>(key.first),
                static_cast<long long>(key.second), static_cast<unsigned long long>(floor.ticks),
                static_cast<unsigned long long>(floor.misses), floor.missed_percent(), floor.worst_late_us,
                static_cast<unsigned long long>(floor.resynchronizations),
                floor.fifo ? ("SCHED_FIFO " + std::to_string(resecto::kCoreFifoPriority)).c_str() : "normal (SCHED_FIFO not permitted)");
  }
  std::printf("misses here are the machine's: these ticks compute nothing, so a tick is late only when the thread did not run\n");
  return 0;
}
