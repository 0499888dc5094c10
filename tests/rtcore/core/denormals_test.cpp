// Subnormal numbers never enter the core's state: the tissue relaxing toward rest drives its
// velocities through the subnormal range, where each operation costs ~100 cycles, and a trainee
// pausing for two minutes found the core slowed by half from then on (audit 10, finding 1).
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <cstdint>
#include <limits>
#include <thread>

#include "rtcore/base/flush_denormals.h"
#include "rtcore/concurrency/job_thread.h"
#include "rtcore/concurrency/loop_helper.h"
#include "rtcore/core/simulation.h"
#include "tests/support/small_simulation.h"

namespace resecto {
namespace {

/// A computation the optimiser cannot fold: the smallest normal double halved is subnormal.
double halved_smallest_normal() {
  volatile double smallest = std::numeric_limits<double>::min();
  return smallest / 2.0;
}

TEST(FlushDenormals, SubnormalsAreZeroInsideTheScopeAndTheCallersModeComesBack) {
  ASSERT_FALSE(denormals_flushed()) << "the test thread starts in IEEE's default mode";
  EXPECT_NE(halved_smallest_normal(), 0.0);
  {
    const FlushDenormals flush;
    EXPECT_TRUE(denormals_flushed());
    EXPECT_EQ(halved_smallest_normal(), 0.0);
  }
  EXPECT_FALSE(denormals_flushed());
  EXPECT_NE(halved_smallest_normal(), 0.0);
}

TEST(FlushDenormals, TheCoresWorkerThreadsFlushThemFromTheirStart) {
  bool job_flushed = false;
  {
    JobThread job([&] { job_flushed = denormals_flushed(); });
    job.launch();
    job.wait();
  }
  EXPECT_TRUE(job_flushed);
  // The helper takes chunks only once it is on call and quick enough to claim one: offer loops until
  // it has run some.
  LoopHelper helper;
  const std::thread::id owner = std::this_thread::get_id();
  std::atomic<int> helper_chunks{0}, helper_chunks_flushed{0};
  auto body = [&](std::uint32_t) {
    if (std::this_thread::get_id() == owner) return;
    helper_chunks.fetch_add(1);
    helper_chunks_flushed.fetch_add(denormals_flushed() ? 1 : 0);
  };
  helper.call_in();
  for (int loop = 0; loop < 100000 && helper_chunks.load() == 0; ++loop) helper.for_each_chunk(64, body);
  helper.send_home();
  ASSERT_GT(helper_chunks.load(), 0);
  EXPECT_EQ(helper_chunks_flushed.load(), helper_chunks.load());
}

/// How many of the tool's pose entries are subnormal.
int subnormal_entries(const ToolPoses& poses) {
  int count = 0;
  for (const RigidPose* pose : {&poses.sheath, &poses.loop}) {
    for (int c = 0; c < 3; ++c) {
      for (int r = 0; r < 3; ++r) count += std::fpclassify(pose->rotation[c][r]) == FP_SUBNORMAL ? 1 : 0;
      count += std::fpclassify(pose->translation[c]) == FP_SUBNORMAL ? 1 : 0;
    }
  }
  return count;
}

TEST(FlushDenormals, AJointComingToRestAtZeroNeverPlacesTheToolWithSubnormals) {
  // A still hand at roll 0: the joint filter's output decays geometrically toward the reading, through
  // the subnormals (from a degree, after about two minutes; from 1e-300 rad, within three seconds).
  auto sim = Simulation::create(testing::small_config());
  ASSERT_TRUE(sim) << sim.error();
  TickInput still;
  still.tool_present = true;
  still.joints.insertion_m = 0.130;
  int subnormal = 0;
  for (std::uint64_t tick = 0; tick < 5 * 960; ++tick) {
    still.joints.roll_rad = tick < 480 ? 1e-300 : 0.0;
    (*sim)->step(still, {});
    subnormal += subnormal_entries((*sim)->tool_poses());
  }
  EXPECT_EQ(subnormal, 0);
  EXPECT_FALSE(denormals_flushed()) << "the step gives its caller back the mode it had";
}

}  // namespace
}  // namespace resecto
