// Hand-driven emulator: key and gamepad mappings, integration within the travel limits, and states
// published on one side reaching the link as the board's own readings.
#include "device/input/manual_motion.h"

#include <GLFW/glfw3.h>
#include <gtest/gtest.h>

#include <set>

#include "device/transport/emulator_transport.h"
#include "tests/device/link_test_support.h"

namespace resecto {
namespace {

TEST(ManualMotion, KeysMapToAxes) {
  const std::set<int> held{GLFW_KEY_W, GLFW_KEY_A, GLFW_KEY_E, GLFW_KEY_X, GLFW_KEY_SPACE};
  const ManualCommand c = command_from_keys([&](int key) { return held.count(key) > 0; });
  EXPECT_EQ(c.insertion, 1.0);
  EXPECT_EQ(c.yaw, -1.0);
  EXPECT_EQ(c.pitch, 0.0);
  EXPECT_EQ(c.roll, 1.0);
  EXPECT_EQ(c.loop, 1.0);
  EXPECT_TRUE(c.cut);
  EXPECT_FALSE(c.coagulate);
  // Opposite keys cancel.
  const ManualCommand both = command_from_keys([](int key) { return key == GLFW_KEY_W || key == GLFW_KEY_S; });
  EXPECT_EQ(both.insertion, 0.0);
}

TEST(ManualMotion, GamepadMappingHasADeadZoneAndUpIsPositive) {
  GLFWgamepadstate pad{};
  pad.axes[GLFW_GAMEPAD_AXIS_LEFT_X] = 0.05f;   // inside the dead zone
  pad.axes[GLFW_GAMEPAD_AXIS_LEFT_Y] = -1.0f;   // stick pushed up
  pad.axes[GLFW_GAMEPAD_AXIS_RIGHT_X] = 0.56f;  // halfway between dead zone and full
  pad.axes[GLFW_GAMEPAD_AXIS_RIGHT_Y] = 0.0f;
  pad.axes[GLFW_GAMEPAD_AXIS_LEFT_TRIGGER] = -1.0f;  // released
  pad.axes[GLFW_GAMEPAD_AXIS_RIGHT_TRIGGER] = 1.0f;  // fully pressed
  pad.buttons[GLFW_GAMEPAD_BUTTON_A] = GLFW_PRESS;
  const ManualCommand c = command_from_gamepad(pad, 0.12);
  EXPECT_EQ(c.yaw, 0.0);
  EXPECT_DOUBLE_EQ(c.pitch, 1.0);
  EXPECT_NEAR(c.roll, 0.5, 1e-6);
  EXPECT_EQ(c.insertion, 0.0);
  EXPECT_DOUBLE_EQ(c.loop, 1.0);
  EXPECT_TRUE(c.cut);
  EXPECT_FALSE(c.coagulate);
}

TEST(ManualMotion, IntegratesWithinTheTravelLimits) {
  ManualMotionLimits limits;
  ManualMotion motion({}, limits);
  ManualCommand c;
  c.insertion = 1.0;
  c.loop = 1.0;
  c.yaw = -1.0;
  for (int i = 0; i < 100; ++i) motion.apply(c, 0.01);  // one second
  EXPECT_NEAR(motion.state().insertion_mm, limits.insertion_rate_mm_s, 1e-9);
  EXPECT_NEAR(motion.state().loop_mm, limits.loop_rate_mm_s, 1e-9);
  EXPECT_NEAR(motion.state().yaw_rad, -limits.yaw_rate_rad_s, 1e-9);
  for (int i = 0; i < 1000; ++i) motion.apply(c, 0.01);  // long past every stop
  EXPECT_EQ(motion.state().insertion_mm, limits.insertion_max_mm);
  EXPECT_EQ(motion.state().loop_mm, limits.loop_max_mm);
  EXPECT_EQ(motion.state().yaw_rad, -limits.yaw_range_rad);
  c = ManualCommand{};
  c.insertion = -1.0;
  for (int i = 0; i < 1000; ++i) motion.apply(c, 0.01);
  EXPECT_EQ(motion.state().insertion_mm, 0.0);
}

TEST(ManualMotion, PublishedStatesReachTheLinkThroughTheBoard) {
  VirtualHostClock clock;
  firmware::Emulator emulator;
  MotionHandoff handoff;
  emulator.set_motion(handoff.script());
  EmulatorTransport board(emulator, clock);
  DeviceLink link(board, clock);
  ManualMotion hand;
  ManualCommand push_in;
  push_in.insertion = 1.0;
  push_in.cut = true;
  std::vector<DeviceSample> samples;
  // Half a second of pushing in at 40 mm/s, published every 10 ms as a console would.
  for (int frame = 0; frame < 50; ++frame) {
    hand.apply(push_in, 0.01);
    handoff.publish(hand.state());
    const std::int64_t frame_end_ns = clock.now_ns() + 10 * kNanosecondsPerMillisecond;
    testing::poll_and_drain(link, samples, [&] { return clock.now_ns() >= frame_end_ns; });
  }
  ASSERT_FALSE(samples.empty());
  const DeviceSample& last = samples.back();
  EXPECT_NEAR(last.joints.insertion_m, 0.020, 0.001);  // 20 mm, within the potentiometer's noise
  EXPECT_EQ(last.pedals & kPedalCut, kPedalCut);
  EXPECT_EQ(link.counters().lost, 0u);
}

}  // namespace
}  // namespace resecto
