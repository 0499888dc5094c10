// The real-time duty window: the spin it allows keeps the last window's running time under the limit,
// and the window forgets what falls out of it.
#include <gtest/gtest.h>

#include "rtcore/core/realtime_duty.h"

namespace resecto {
namespace {

TEST(RealtimeDuty, UnlimitedAllowsEverySpin) {
  RealtimeDuty duty(4, 0);
  duty.record(1'000'000);
  EXPECT_FALSE(duty.limited());
  EXPECT_EQ(duty.allowed_spin_ns(250'000, 900'000), 250'000);
}

TEST(RealtimeDuty, SpinShrinksToTheRoomLeftAndThenToNothing) {
  // A window of 4 cycles that may hold 3 ms of running time.
  RealtimeDuty duty(4, 3'000'000);
  for (int i = 0; i < 4; ++i) duty.record(600'000);
  // The oldest 600 us drops out when this cycle is recorded: 1.8 ms in the window, 0.9 ms busy now.
  EXPECT_EQ(duty.window_busy_ns(), 1'800'000);
  EXPECT_EQ(duty.allowed_spin_ns(250'000, 900'000), 250'000) << "0.3 ms of room: the whole spin";
  EXPECT_EQ(duty.allowed_spin_ns(250'000, 1'100'000), 100'000) << "0.1 ms of room";
  EXPECT_EQ(duty.allowed_spin_ns(250'000, 1'300'000), 0) << "no room: sleep";
  EXPECT_EQ(duty.allowed_spin_ns(-5, 0), 0) << "a negative wish spins nothing";
}

TEST(RealtimeDuty, TheWindowForgetsWhatFallsOutOfIt) {
  RealtimeDuty duty(3, 1'000'000);
  duty.record(900'000);
  duty.record(100'000);
  duty.record(100'000);
  EXPECT_EQ(duty.allowed_spin_ns(500'000, 0), 500'000) << "the 0.9 ms cycle is the one about to drop out";
  duty.record(100'000);  // it drops out
  EXPECT_EQ(duty.window_busy_ns(), 200'000);
}

TEST(RealtimeDuty, ReadsTheKernelsBandwidthAsAFraction) {
  const std::optional<double> fraction = realtime_bandwidth_fraction();
  if (fraction) {
    EXPECT_GT(*fraction, 0.0);
    EXPECT_LE(*fraction, 1.0);
    EXPECT_NEAR(realtime_busy_limit(), std::max(0.0, *fraction - 0.05), 1e-12);
  } else {
    EXPECT_EQ(realtime_busy_limit(), 0.0) << "no kernel limit, no duty limit";
  }
}

}  // namespace
}  // namespace resecto
