// ToolInput: the first reading places the tool; a disconnection freezes it with the pedals released;
// after reconnection it slews at the limits, with the pedals released until it has caught up.
#include "device/link/tool_input.h"

#include <gtest/gtest.h>

namespace resecto {
namespace {

DeviceSample sample(double insertion_m, double yaw_rad, std::uint8_t pedals = kPedalCut) {
  DeviceSample s;
  s.joints.insertion_m = insertion_m;
  s.joints.yaw_rad = yaw_rad;
  s.pedals = pedals;
  return s;
}

DeviceSample event(LinkEvent e) {
  DeviceSample s;
  s.event = e;
  return s;
}

TEST(ToolInput, FreezesOnDisconnectAndSlewsBackAtTheLimits) {
  SpscRing<DeviceSample> ring(16);
  ReengageLimits limits;
  limits.max_linear_speed_m_s = 0.1;
  limits.max_angular_speed_rad_s = 1.0;
  ToolInput tool(limits);
  const double tick = 0.001;

  tool.latch(ring, tick);
  EXPECT_EQ(tool.state(), ToolInputState::kNoDevice);
  ASSERT_TRUE(ring.try_push(event(LinkEvent::kConnected)));
  ASSERT_TRUE(ring.try_push(sample(0.160, 0.3)));
  tool.latch(ring, tick);
  EXPECT_EQ(tool.state(), ToolInputState::kTracking);
  EXPECT_EQ(tool.joints().insertion_m, 0.160);  // first reading: placed, not slewed
  EXPECT_EQ(tool.pedals(), kPedalCut);

  // A sample, then the unplug, in one tick: the tool ends at that sample and freezes.
  ASSERT_TRUE(ring.try_push(sample(0.161, 0.3)));
  ASSERT_TRUE(ring.try_push(event(LinkEvent::kDisconnected)));
  tool.latch(ring, tick);
  EXPECT_EQ(tool.state(), ToolInputState::kFrozen);
  EXPECT_EQ(tool.joints().insertion_m, 0.161);
  EXPECT_EQ(tool.pedals(), 0);
  for (int i = 0; i < 100; ++i) tool.latch(ring, tick);
  EXPECT_EQ(tool.joints().insertion_m, 0.161);

  // Back 10 mm further in and 0.05 rad turned: 100 ticks for insertion at 0.1 m/s, 50 for yaw.
  ASSERT_TRUE(ring.try_push(event(LinkEvent::kConnected)));
  ASSERT_TRUE(ring.try_push(sample(0.171, 0.35)));
  int ticks = 0;
  do {
    const DeviceJoints before = tool.joints();
    tool.latch(ring, tick);
    ++ticks;
    EXPECT_LE(tool.joints().insertion_m - before.insertion_m, 0.1 * tick + 1e-15);
    EXPECT_LE(tool.joints().yaw_rad - before.yaw_rad, 1.0 * tick + 1e-15);
    if (tool.state() == ToolInputState::kReengaging) {
      EXPECT_EQ(tool.pedals(), 0);
    }
  } while (tool.state() != ToolInputState::kTracking && ticks < 1000);
  EXPECT_NEAR(ticks, 100, 1);  // 10 mm at 0.1 mm per tick, give or take the rounding of the steps
  EXPECT_EQ(tool.joints().insertion_m, 0.171);
  EXPECT_EQ(tool.joints().yaw_rad, 0.35);
  EXPECT_EQ(tool.pedals(), kPedalCut);
  EXPECT_EQ(tool.disconnections_seen(), 1u);
}

TEST(ToolInput, ReengagingFollowsAMovingTarget) {
  SpscRing<DeviceSample> ring(16);
  ToolInput tool;
  ASSERT_TRUE(ring.try_push(sample(0.150, 0.0)));
  tool.latch(ring, 0.001);
  ASSERT_TRUE(ring.try_push(event(LinkEvent::kDisconnected)));
  ASSERT_TRUE(ring.try_push(event(LinkEvent::kConnected)));
  tool.latch(ring, 0.001);
  EXPECT_EQ(tool.state(), ToolInputState::kReengaging);
  // The hand keeps moving; the tool converges and then tracks exactly.
  for (int i = 0; i < 2000; ++i) {
    ASSERT_TRUE(ring.try_push(sample(0.160 + 1e-6 * i, 0.0)));
    tool.latch(ring, 0.001);
  }
  EXPECT_EQ(tool.state(), ToolInputState::kTracking);
  EXPECT_EQ(tool.joints().insertion_m, 0.160 + 1e-6 * 1999);
}

}  // namespace
}  // namespace resecto
