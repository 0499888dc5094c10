// The machine's own floor for real-time deadlines: the core's FixedStepScheduler at the real-time
// run's settings (the default tick rate, the core's FIFO priority, the default spin), running ticks that
// only burn a fixed time on the CPU: no simulation, no memory traffic, no other thread. Whatever it
// misses, the machine missed: on a virtual machine the host takes the vCPU away for milliseconds now
// and then, and a tick caught in that is late whatever it computes, with the ticks that catch up after
// it. Printed beside what `resecto run --realtime` reports, it says how much of that figure the
// simulator could still remove. Args: busy time per tick (us), seconds.
// A tick that burns wall-clock time ends on time when the vCPU comes back before its end, and runs no
// slower when the host shares the physical core with another guest: that floor counts only the
// longest stalls. BM_DeadlineFloorWork's ticks do a fixed amount of arithmetic instead (as long as the
// busy time on this machine at its quickest), so a stall or a slow stretch delays them as it delays a
// physics step: the floor a computing tick has. The real-time figures are judged against the first;
// the second tells how much of the rest is the machine's.
// BM_DeadlineFloorShared's ticks do the same fixed work in chunks shared with a helper thread, as the
// core shares its physics step (LoopHelper, the helper at the core's priority on the other processor,
// keep_core_apart): a tick then waits on both processors, and a stall of either one while it holds a
// chunk delays the tick. That is the floor of a real-time run with two physics threads, which no
// single-threaded floor shows (session 45: the 8640 demo's late ticks came with neither of the
// core's threads descheduled in the guest's own scheduler trace, on either processor).
#include <benchmark/benchmark.h>

#include <pthread.h>
#include <sched.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <map>
#include <string>
#include <tuple>

#include "rtcore/concurrency/loop_helper.h"
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
/// What a floor's ticks do; the table lists the busy-waiting floors first.
enum class TickKind { kBusyWaiting, kFixedWork, kSharedWork };
const char* name(TickKind kind) {
  switch (kind) {
    case TickKind::kBusyWaiting: return "busy waiting";
    case TickKind::kFixedWork: return "fixed work";
    case TickKind::kSharedWork: return "fixed work on two threads";
  }
  return "";
}
/// Per kind of tick, busy time (us) and seconds: the floor measured.
std::map<std::tuple<TickKind, std::int64_t, std::int64_t>, Floor>& floors() {
  static std::map<std::tuple<TickKind, std::int64_t, std::int64_t>, Floor> f;
  return f;
}

void burn_until(std::int64_t until_ns) {
  while (FrameProfiler::now_ns() < until_ns) {
  }
}

using WorkArray = std::array<double, 1024>;
WorkArray fresh_work_array() {
  WorkArray v{};
  for (std::size_t i = 0; i < v.size(); ++i) v[i] = 1.0 + 1e-3 * static_cast<double>(i);
  return v;
}

/// A fixed amount of floating-point work over an L1-sized array: `rounds` passes.
double work(WorkArray& values, std::int64_t rounds) {
  double sum = 0.0;
  for (std::int64_t r = 0; r < rounds; ++r) {
    for (double& v : values) {
      v = v * 0.999999 + 1e-6;
      sum += v;
    }
    benchmark::DoNotOptimize(values.data());
  }
  return sum;
}
double work(std::int64_t rounds) {
  static WorkArray values = fresh_work_array();
  return work(values, rounds);
}

/// The least time of `trials` runs of work(rounds): the machine at its quickest, whatever slow
/// stretch some of the runs fell in.
std::int64_t quickest_ns(std::int64_t rounds, int trials) {
  std::int64_t quickest = std::numeric_limits<std::int64_t>::max();
  for (int trial = 0; trial < trials; ++trial) {
    const std::int64_t start = FrameProfiler::now_ns();
    benchmark::DoNotOptimize(work(rounds));
    quickest = std::min(quickest, std::max<std::int64_t>(1, FrameProfiler::now_ns() - start));
  }
  return quickest;
}

/// Passes of work() that take `busy_us` on this machine at its quickest.
std::int64_t rounds_for(std::int64_t busy_us) {
  constexpr std::int64_t kTrialRounds = 64;
  return std::max<std::int64_t>(1, busy_us * 1000 * kTrialRounds / quickest_ns(kTrialRounds, 200));
}

/// Runs `seconds` of ticks at the real-time settings, each calling `tick_work`.
/// `helper`, if any, is called in whenever the core wakes for a tick, as the simulation calls in its own.
template <typename TickWork>
Floor run_floor(std::int64_t seconds, const TickWork& tick_work, LoopHelper* helper = nullptr) {
  // The default rates, rounded to a period as the headless runner rounds them.
  const double tick_s = SimulationConfig{}.tick_s();
  SchedulerConfig config;
  config.period_ns = static_cast<std::int64_t>(std::llround(tick_s * 1e9));
  config.realtime = true;
  config.spin_ns = kDefaultRealtimeSpinUs * 1000;
  FixedStepScheduler scheduler(config);
  const ScopedFifoPriority priority(kCoreFifoPriority);
  if (helper != nullptr) scheduler.set_wake_hook([](void* h) { static_cast<LoopHelper*>(h)->call_in(); }, helper);
  const auto ticks = static_cast<std::uint64_t>(std::llround(static_cast<double>(seconds) / tick_s));
  scheduler.run(0, ticks, [&](std::uint64_t) {
    tick_work();
    return true;
  });
  if (helper != nullptr) helper->send_home();
  const DeadlineReport& report = scheduler.report();
  return {report.ticks, report.misses, report.resynchronizations, report.max_late_us, priority.raised()};
}

void count(benchmark::State& state, const Floor& floor) {
  state.counters["misses"] = static_cast<double>(floor.misses);
  state.counters["miss_percent"] = floor.missed_percent();
  state.counters["worst_late_us"] = floor.worst_late_us;
  state.counters["sched_fifo"] = floor.fifo ? 1 : 0;
}

void BM_DeadlineFloor(benchmark::State& state) {
  const std::int64_t busy_us = state.range(0), seconds = state.range(1);
  Floor& floor = floors()[{TickKind::kBusyWaiting, busy_us, seconds}];
  for (auto _ : state) floor = run_floor(seconds, [&] { burn_until(FrameProfiler::now_ns() + busy_us * 1000); });
  count(state, floor);
}
// 300 us: the 8640-triangle model's physics step (tissue_bench, 2026-11-23); 0: the schedule alone.
BENCHMARK(BM_DeadlineFloor)->Args({300, 10})->Args({0, 10})->Iterations(1)->UseRealTime()->Unit(benchmark::kMillisecond);

void BM_DeadlineFloorWork(benchmark::State& state) {
  const std::int64_t busy_us = state.range(0), seconds = state.range(1);
  Floor& floor = floors()[{TickKind::kFixedWork, busy_us, seconds}];
  const std::int64_t rounds = rounds_for(busy_us);
  for (auto _ : state) floor = run_floor(seconds, [&] { benchmark::DoNotOptimize(work(rounds)); });
  count(state, floor);
  // The calibration's check: what a tick's work takes here afterwards, at its quickest.
  state.counters["tick_work_us"] = static_cast<double>(quickest_ns(rounds, 20)) / 1000.0;
}
BENCHMARK(BM_DeadlineFloorWork)->Args({300, 10})->Iterations(1)->UseRealTime()->Unit(benchmark::kMillisecond);

/// The physics step's shape: its loops cut into chunks the core and the helper claim from either end.
constexpr std::uint32_t kSharedChunks = 16;

void BM_DeadlineFloorShared(benchmark::State& state) {
  const std::int64_t busy_us = state.range(0), seconds = state.range(1);
  Floor& floor = floors()[{TickKind::kSharedWork, busy_us, seconds}];
  // Each chunk a 1/kSharedChunks share of the single thread's busy time, on an array of its own.
  const std::int64_t rounds = std::max<std::int64_t>(1, rounds_for(busy_us) / kSharedChunks);
  std::array<WorkArray, kSharedChunks> arrays;
  arrays.fill(fresh_work_array());
  std::array<double, kSharedChunks> sums{};
  LoopHelper helper;
  const bool helper_raised = raise_to_fifo(helper.native_handle(), kCoreFifoPriority);
  auto chunk = [&](std::uint32_t c) { sums[c] = work(arrays[c], rounds); };
  cpu_set_t allowed;  // this thread's processors, given back after: the benchmarks after it may use them all
  CPU_ZERO(&allowed);
  const bool restorable = pthread_getaffinity_np(pthread_self(), sizeof allowed, &allowed) == 0;
  for (auto _ : state) {
    // The processors as raise_simulation_threads() gives them to a real-time run's core and helper.
    const pthread_t others[] = {helper.native_handle()};
    state.counters["core_cpu"] = keep_core_apart(pthread_self(), others);
    floor = run_floor(seconds, [&] { helper.for_each_chunk(kSharedChunks, chunk); }, &helper);
  }
  if (restorable) (void)pthread_setaffinity_np(pthread_self(), sizeof allowed, &allowed);
  benchmark::DoNotOptimize(sums.data());
  floor.fifo = floor.fifo && helper_raised;
  count(state, floor);
  state.counters["helper_share"] = static_cast<double>(helper.chunks_helped()) / static_cast<double>(std::max<std::uint64_t>(1, helper.chunks_offered()));
}
BENCHMARK(BM_DeadlineFloorShared)->Args({300, 10})->Iterations(1)->UseRealTime()->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace resecto

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  std::printf("\n%10s %8s | %8s %8s %10s %12s %12s | %s\n", "busy us", "seconds", "ticks", "misses", "missed %", "worst late us",
              "re-anchored", "scheduling, ticks");
  bool kinds[3] = {false, false, false};
  for (const auto& [key, floor] : resecto::floors()) {
    const auto& [kind, busy_us, seconds] = key;
    kinds[static_cast<int>(kind)] = true;
    std::printf("%10lld %8lld | %8llu %8llu %9.3f%% %12.0f %12llu | %s, %s\n", static_cast<long long>(busy_us),
                static_cast<long long>(seconds), static_cast<unsigned long long>(floor.ticks),
                static_cast<unsigned long long>(floor.misses), floor.missed_percent(), floor.worst_late_us,
                static_cast<unsigned long long>(floor.resynchronizations),
                floor.fifo ? ("SCHED_FIFO " + std::to_string(resecto::kCoreFifoPriority)).c_str() : "normal (SCHED_FIFO not permitted)",
                resecto::name(kind));
  }
  if (kinds[0]) std::printf("busy waiting: a tick is late only when the thread did not run until past its deadline\n");
  if (kinds[1]) {
    std::printf(
        "fixed work: a tick is late also when a stall or a slow stretch of the machine delays its work, as it delays a physics step\n");
  }
  if (kinds[2]) {
    std::printf("fixed work on two threads: the same work in chunks shared with a helper on the other processor, as the physics step is:\n"
                "  a stall of either processor while it holds a chunk delays the tick\n");
  }
  return 0;
}
