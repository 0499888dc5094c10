// Unplug and replug in the middle of motion, on the emulator in virtual time: the disconnection is
// reported within the silence timeout, the tool stays frozen while the device is away (pedals
// released), and after reconnection it moves to the device's new readings without a jump.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "device/link/tool_input.h"
#include "device/transport/emulator_transport.h"
#include "device/transport/fault_injection.h"
#include "tests/device/link_test_support.h"

namespace resecto {
namespace {

using testing::smooth_motion;

/// The emulator, the fault wrapper, the link and the core's latch, stepped together.
struct Rig {
  VirtualHostClock clock;
  firmware::Emulator emulator;
  EmulatorTransport board{emulator, clock};
  FaultInjectingTransport faulty{board, clock, FaultConfig{}};
  DeviceLink link{faulty, clock};
  ToolInput tool;
  std::int64_t last_latch_ns = 0;
  std::vector<DeviceSample> events;  ///< connection events as the core saw them
  DeviceSample newest;               ///< the newest sample the ring delivered

  Rig() { emulator.set_motion(&smooth_motion); }

  /// One link poll, then one core tick over the time that passed.
  void step() {
    link.poll_once();
    const std::int64_t now_ns = clock.now_ns();
    // Note what the ring carries, then hand it on to the latch through a ring of its own.
    DeviceSample entry;
    while (link.samples().try_pop(entry)) {
      if (entry.event == LinkEvent::kSample) newest = entry;
      else events.push_back(entry);
      ASSERT_TRUE(relay.try_push(entry));
    }
    tool.latch(relay, static_cast<double>(now_ns - last_latch_ns) * 1e-9);
    last_latch_ns = now_ns;
  }
  void run_until_ns(std::int64_t t_ns) {
    while (clock.now_ns() < t_ns) step();
  }
  SpscRing<DeviceSample> relay{8192};
};

double max_joint_difference_scaled(const DeviceJoints& a, const DeviceJoints& b, const ReengageLimits& l) {
  // Each joint's change divided by its speed limit: the time in seconds the change needs.
  return std::max({std::abs(a.yaw_rad - b.yaw_rad) / l.max_angular_speed_rad_s,
                   std::abs(a.pitch_rad - b.pitch_rad) / l.max_angular_speed_rad_s,
                   std::abs(a.roll_rad - b.roll_rad) / l.max_angular_speed_rad_s,
                   std::abs(a.insertion_m - b.insertion_m) / l.max_linear_speed_m_s,
                   std::abs(a.loop_travel_m - b.loop_travel_m) / l.max_linear_speed_m_s});
}

TEST(Unplug, ToolFreezesThenResumesFromNewReadingsWithoutAJump) {
  Rig rig;
  // t = 2 s: insertion is moving at its fastest (31 mm/s).
  rig.run_until_ns(2 * kNanosecondsPerSecond);
  ASSERT_EQ(rig.tool.state(), ToolInputState::kTracking);
  ASSERT_TRUE(rig.link.connected());
  const DeviceJoints frozen = rig.tool.joints();
  EXPECT_EQ(frozen.insertion_m, rig.newest.joints.insertion_m);

  const std::int64_t unplug_ns = rig.clock.now_ns();
  rig.faulty.unplug_now();  // 300 ms without the device
  while (rig.link.connected()) rig.step();
  ASSERT_FALSE(rig.events.empty());
  const DeviceSample& disconnected = rig.events.back();
  ASSERT_EQ(disconnected.event, LinkEvent::kDisconnected);
  EXPECT_LE(disconnected.host_time_ns - unplug_ns, rig.link.config().silence_timeout_ns);

  // Frozen, bit for bit, with the pedals released, for as long as the device is away.
  int frozen_ticks = 0;
  for (;;) {
    rig.step();
    if (rig.link.connected()) break;
    ASSERT_EQ(rig.tool.state(), ToolInputState::kFrozen);
    ASSERT_EQ(rig.tool.joints().insertion_m, frozen.insertion_m);
    ASSERT_EQ(rig.tool.joints().yaw_rad, frozen.yaw_rad);
    ASSERT_EQ(rig.tool.joints().loop_travel_m, frozen.loop_travel_m);
    ASSERT_EQ(rig.tool.pedals(), 0);
    ++frozen_ticks;
  }
  const std::int64_t reconnect_ns = rig.clock.now_ns();
  EXPECT_GE(reconnect_ns - unplug_ns, 300 * kNanosecondsPerMillisecond);  // not before the replug
  EXPECT_LE(reconnect_ns - unplug_ns, 700 * kNanosecondsPerMillisecond);  // backoff: 20, 40, ... ms
  EXPECT_GT(frozen_ticks, 0);

  // Re-engaging: never faster than the limits, until it tracks the device again.
  const ReengageLimits limits;
  DeviceJoints previous = rig.tool.joints();
  std::int64_t previous_ns = rig.clock.now_ns();
  bool saw_reengaging = false;
  while (rig.tool.state() != ToolInputState::kTracking) {
    rig.step();
    ASSERT_LT(rig.clock.now_ns(), reconnect_ns + 2 * kNanosecondsPerSecond) << "never caught up";
    const double dt_s = static_cast<double>(rig.clock.now_ns() - previous_ns) * 1e-9;
    ASSERT_LE(max_joint_difference_scaled(rig.tool.joints(), previous, limits), dt_s * (1 + 1e-9) + 1e-12);
    saw_reengaging |= rig.tool.state() == ToolInputState::kReengaging;
    previous = rig.tool.joints();
    previous_ns = rig.clock.now_ns();
  }
  EXPECT_TRUE(saw_reengaging);
  rig.run_until_ns(rig.clock.now_ns() + 50 * kNanosecondsPerMillisecond);

  // Motion resumed from the device's new readings: the tool is where the hand is now.
  const DeviceJoints now = rig.tool.joints();
  EXPECT_EQ(now.insertion_m, rig.newest.joints.insertion_m);
  EXPECT_GT(std::abs(now.insertion_m - frozen.insertion_m), 0.005);
  const firmware::MotionState hand = smooth_motion(rig.newest.device_time_us);
  EXPECT_NEAR(now.insertion_m, hand.insertion_mm * 1e-3, 0.5e-3);
  EXPECT_NEAR(now.yaw_rad, hand.yaw_rad, 2 * 2 * std::numbers::pi / 4096);

  const LinkCounters c = rig.link.counters();
  EXPECT_EQ(c.disconnects, 1u);
  EXPECT_EQ(c.connects, 2u);
  EXPECT_EQ(c.lost, 0u);  // what went by while unplugged is not loss...
  // ...but is counted apart: about one report per millisecond away.
  EXPECT_GE(c.missed_while_disconnected, 250u);
  EXPECT_EQ(rig.tool.disconnections_seen(), 1u);
}

TEST(Unplug, SilenceLongerThanTheTimeoutMeansDisconnected) {
  Rig rig;
  rig.run_until_ns(500 * kNanosecondsPerMillisecond);
  const DeviceJoints before = rig.tool.joints();
  const std::int64_t last_report_ns = rig.newest.host_time_ns;
  rig.emulator.stall_main_loop(250'000);  // the board stops sending for 250 ms
  while (rig.link.connected()) rig.step();
  const DeviceSample& disconnected = rig.events.back();
  ASSERT_EQ(disconnected.event, LinkEvent::kDisconnected);
  const std::int64_t silence_ns = disconnected.host_time_ns - last_report_ns;
  EXPECT_GE(silence_ns, rig.link.config().silence_timeout_ns);
  EXPECT_LE(silence_ns, rig.link.config().silence_timeout_ns + kNanosecondsPerMillisecond);
  EXPECT_EQ(rig.link.counters().silence_timeouts, 1u);
  EXPECT_NE(rig.link.last_error().find("no valid report for"), std::string::npos) << rig.link.last_error();
  EXPECT_EQ(rig.tool.state(), ToolInputState::kFrozen);
  EXPECT_EQ(rig.tool.joints().insertion_m, before.insertion_m);
  // The board comes back by itself; so does the link, and the tool tracks again.
  rig.run_until_ns(rig.clock.now_ns() + 1500 * kNanosecondsPerMillisecond);
  EXPECT_TRUE(rig.link.connected());
  EXPECT_EQ(rig.tool.state(), ToolInputState::kTracking);
}

}  // namespace
}  // namespace resecto
