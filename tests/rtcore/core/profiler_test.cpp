// The frame-budget profiler: percentiles within the histogram's 1% resolution, budgets counted, and
// a trace Perfetto can open.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <filesystem>
#include <fstream>
#include <random>
#include <vector>
#include <unistd.h>

#include <nlohmann/json.hpp>

#include "rtcore/core/profiler.h"

namespace resecto {
namespace {

TEST(TimingHistogram, QuantilesWithinOnePercentOfExact) {
  std::mt19937_64 random(7);
  std::lognormal_distribution<double> durations(4.0, 1.0);  // a long-tailed timing distribution, µs
  std::vector<double> samples(20000);
  TimingHistogram histogram;
  for (double& s : samples) {
    s = durations(random);
    histogram.add(s);
  }
  std::sort(samples.begin(), samples.end());
  for (double q : {0.5, 0.95, 0.99}) {
    const double exact = samples[static_cast<std::size_t>(std::ceil(q * samples.size())) - 1];
    EXPECT_NEAR(histogram.quantile(q) / exact, 1.0, 0.011) << "q = " << q;
  }
  EXPECT_DOUBLE_EQ(histogram.max(), samples.back());
  EXPECT_EQ(histogram.count(), samples.size());
}

TEST(FrameProfiler, CountsOverBudgetAndWritesATrace) {
  std::array<double, kStageCount> budgets{};
  budgets.fill(100.0);
  FrameProfiler profiler(budgets, 8);
  for (std::uint64_t tick = 0; tick < 10; ++tick) {
    profiler.record(Stage::kPhysics, tick, 1'000'000 * tick, 1'000'000 * tick + (tick < 7 ? 50'000 : 150'000));
    profiler.record(Stage::kQuery, tick, 1'000'000 * tick + 200'000, 1'000'000 * tick + 230'000);
  }
  const StageStatistics physics = profiler.statistics(Stage::kPhysics);
  EXPECT_EQ(physics.samples, 10u);
  EXPECT_EQ(physics.over_budget, 3u);
  EXPECT_NEAR(physics.median_us, 50.0, 0.6);
  EXPECT_DOUBLE_EQ(physics.max_us, 150.0);
  EXPECT_EQ(profiler.trace_dropped(), 12u);  // 20 recorded, 8 kept
  EXPECT_EQ(profiler.trace_capacity(), 8u);
  EXPECT_EQ(profiler.trace_first_tick(), 6u);  // ticks 6 to 9, two stages each

  const auto path = std::filesystem::temp_directory_path() / ("resecto_trace_" + std::to_string(::getpid()) + ".json");
  ASSERT_TRUE(profiler.write_chrome_trace(path));
  const auto trace = nlohmann::json::parse(std::ifstream(path));
  int complete = 0;
  double last_ts = -1.0;
  for (const auto& event : trace.at("traceEvents")) {
    if (event.at("ph") != "X") continue;
    ++complete;
    EXPECT_GE(event.at("ts").get<double>(), last_ts);  // oldest first
    last_ts = event.at("ts").get<double>();
    EXPECT_GT(event.at("dur").get<double>(), 0.0);
  }
  EXPECT_EQ(complete, 8);
  std::filesystem::remove(path);
}

TEST(FrameProfiler, ATraceOfManyBlocksIsWrittenWhole) {
  // About 100 bytes an event: 40,000 events are four of the writer's 1 MB blocks.
  std::array<double, kStageCount> budgets{};
  budgets.fill(100.0);
  FrameProfiler profiler(budgets, 40'000);
  for (std::uint64_t tick = 0; tick < 40'000; ++tick) profiler.record(Stage::kTick, tick, 1'000 * static_cast<std::int64_t>(tick), 1'000 * static_cast<std::int64_t>(tick) + 500);
  const auto path = std::filesystem::temp_directory_path() / ("resecto_long_trace_" + std::to_string(::getpid()) + ".json");
  ASSERT_TRUE(profiler.write_chrome_trace(path));
  EXPECT_GT(std::filesystem::file_size(path), 3u << 20);
  const auto trace = nlohmann::json::parse(std::ifstream(path));
  std::uint64_t expected_tick = 0;
  for (const auto& event : trace.at("traceEvents")) {
    if (event.at("ph") != "X") continue;
    EXPECT_EQ(event.at("args").at("tick").get<std::uint64_t>(), expected_tick);
    ++expected_tick;
  }
  EXPECT_EQ(expected_tick, 40'000u);
  std::filesystem::remove(path);
}

TEST(FrameProfiler, AnotherThreadsSpansGetATrackOfTheirOwnOnTheSameClock) {
  // The console's frames beside the core's stages: a named track (tid 3), each span with its number
  // and tick, placed on the same time axis (the earliest event, here a frame, is time zero).
  std::array<double, kStageCount> budgets{};
  budgets.fill(100.0);
  FrameProfiler profiler(budgets, 16);
  for (std::uint64_t tick = 0; tick < 4; ++tick) profiler.record(Stage::kTick, tick, 1'000'000 + 1'000'000 * static_cast<std::int64_t>(tick), 1'200'000 + 1'000'000 * static_cast<std::int64_t>(tick));
  const std::vector<TraceSpan> frames{{500'000, 2'000'000, 0, 0}, {2'500'000, 2'000'000, 1, 2}};
  const std::array<TraceTrack, 1> tracks{TraceTrack{"console (frames)", "frame", "frame", frames}};
  const auto path = std::filesystem::temp_directory_path() / ("resecto_tracks_" + std::to_string(::getpid()) + ".json");
  ASSERT_TRUE(profiler.write_chrome_trace(path, tracks));
  const auto trace = nlohmann::json::parse(std::ifstream(path));
  std::filesystem::remove(path);
  bool named = false;
  std::vector<nlohmann::json> frame_events, tick_events;
  for (const auto& event : trace.at("traceEvents")) {
    if (event.at("ph") == "M" && event.at("tid") == 3) named = event.at("args").at("name") == "console (frames)";
    if (event.at("ph") != "X") continue;
    (event.at("tid") == 3 ? frame_events : tick_events).push_back(event);
  }
  EXPECT_TRUE(named);
  ASSERT_EQ(frame_events.size(), 2u);
  ASSERT_EQ(tick_events.size(), 4u);
  EXPECT_EQ(frame_events[0].at("name"), "frame");
  EXPECT_DOUBLE_EQ(frame_events[0].at("ts").get<double>(), 0.0);
  EXPECT_DOUBLE_EQ(frame_events[1].at("ts").get<double>(), 2000.0);
  EXPECT_DOUBLE_EQ(frame_events[1].at("dur").get<double>(), 2000.0);
  EXPECT_EQ(frame_events[1].at("args").at("frame"), 1);
  EXPECT_EQ(frame_events[1].at("args").at("tick"), 2);
  EXPECT_DOUBLE_EQ(tick_events[0].at("ts").get<double>(), 500.0);  // 1 ms on the clock, the frame at 0.5 ms
}

}  // namespace
}  // namespace resecto
