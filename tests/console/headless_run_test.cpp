// The headless runner in-process: a snapshot consumer slowed on purpose changes nothing in the core
// (same hash at every collision step), because the core never waits for it.
#include <gtest/gtest.h>

#include "console/headless/headless_run.h"

namespace resecto {
namespace {

HeadlessOptions short_demo() {
  HeadlessOptions options;
  Result<Procedure> demo = builtin_procedure("demo");
  EXPECT_TRUE(demo);
  options.procedure = *demo;
  options.seconds = 2.0;
  options.simulation.prostate_triangles = 1296;
  return options;
}

TEST(HeadlessRun, SlowConsumerGivesTheSameHashesAtEveryCollisionStep) {
  HeadlessOptions fast = short_demo();
  HeadlessOptions slow = short_demo();
  slow.consumer_delay_ms = 25.0;  // takes a snapshot every 25 ms while the core publishes faster
  Result<HeadlessResult> a = run_headless(fast);
  Result<HeadlessResult> b = run_headless(slow);
  ASSERT_TRUE(a && b);
  ASSERT_EQ(a->collision_hashes.size(), 120u);
  EXPECT_EQ(a->collision_hashes, b->collision_hashes);
  EXPECT_EQ(a->final_hash, b->final_hash);
  // The slow consumer really was slow: at most one snapshot per 25 ms of the run (on a normal build
  // far fewer than the 120 published; a sanitizer build may run slowly enough to see them all).
  const double wall_ms = b->report.at("wall_s").get<double>() * 1000.0;
  EXPECT_LE(static_cast<double>(b->report.at("snapshots").at("received").get<std::uint64_t>()), wall_ms / 25.0 + 1.0);
}

TEST(HeadlessRun, TheToolStaysWithdrawnUntilTheDeviceReports) {
  HeadlessOptions options = short_demo();
  options.seconds = 0.5;
  Result<HeadlessResult> run = run_headless(options);
  ASSERT_TRUE(run);
  EXPECT_GT(run->report.at("device").at("accepted").get<std::uint64_t>(), 490u);
  EXPECT_EQ(run->report.at("device").at("rejected").get<std::uint64_t>(), 0u);
}

}  // namespace
}  // namespace resecto
