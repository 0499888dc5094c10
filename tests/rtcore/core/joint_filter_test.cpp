// The device readings' smoothing: a still, noisy reading comes out several times quieter; a steady
// motion is followed with a small, bounded lag and a stop is reached exactly; off means untouched.
#include "rtcore/core/joint_filter.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace resecto {
namespace {

constexpr double kTickS = 1.0 / 960.0;

TEST(JointFilter, QuietensAStillNoisyReadingSeveralFold) {
  // The emulated potentiometer's noise on the sheath: 0.18 mm RMS around 160 mm.
  std::mt19937_64 random(3);
  std::normal_distribution<double> noise(0.0, 0.00018);
  JointFilter filter;
  DeviceJoints still;
  still.insertion_m = 0.160;
  filter.reset(still);
  double in2 = 0.0, out2 = 0.0;
  int samples = 0;
  for (int tick = 0; tick < 4 * 960; ++tick) {
    DeviceJoints reading = still;
    reading.insertion_m += noise(random);
    const DeviceJoints out = filter.filter(reading, kTickS);
    if (tick < 960) continue;  // settled
    in2 += (reading.insertion_m - still.insertion_m) * (reading.insertion_m - still.insertion_m);
    out2 += (out.insertion_m - still.insertion_m) * (out.insertion_m - still.insertion_m);
    ++samples;
  }
  const double in_rms = std::sqrt(in2 / samples), out_rms = std::sqrt(out2 / samples);
  EXPECT_NEAR(in_rms, 0.00018, 0.00001);
  EXPECT_LT(out_rms, in_rms / 5.0) << "RMS in " << in_rms * 1e3 << " mm, out " << out_rms * 1e3 << " mm";
}

TEST(JointFilter, FollowsASteadyMotionWithABoundedLagAndReachesTheStop) {
  JointFilter filter;
  DeviceJoints reading;
  reading.insertion_m = 0.150;
  reading.roll_rad = 0.0;
  filter.reset(reading);
  DeviceJoints out;
  double worst_lag_m = 0.0;
  for (int tick = 1; tick <= 960; ++tick) {  // 1 s at 30 mm/s and 1 rad/s
    reading.insertion_m = 0.150 + 0.030 * tick * kTickS;
    reading.roll_rad = 1.0 * tick * kTickS;
    out = filter.filter(reading, kTickS);
    EXPECT_LE(out.insertion_m, reading.insertion_m);  // never overshoots a steady motion
    worst_lag_m = std::max(worst_lag_m, reading.insertion_m - out.insertion_m);
  }
  EXPECT_GT(worst_lag_m, 0.0);
  EXPECT_LT(worst_lag_m, 0.001) << "lag " << worst_lag_m * 1e3 << " mm at 30 mm/s";
  EXPECT_LT(reading.roll_rad - out.roll_rad, 0.02);
  for (int tick = 0; tick < 2 * 960; ++tick) out = filter.filter(reading, kTickS);  // held
  EXPECT_NEAR(out.insertion_m, reading.insertion_m, 1e-7);
  EXPECT_NEAR(out.roll_rad, reading.roll_rad, 1e-6);
}

TEST(JointFilter, OffPassesTheReadingsThroughAndResetPlacesExactly) {
  JointFilterSettings off;
  off.enabled = false;
  JointFilter raw(off), smooth;
  DeviceJoints a, b;
  a.yaw_rad = 0.1, a.insertion_m = 0.16, a.loop_travel_m = 0.01;
  b.yaw_rad = 0.2, b.insertion_m = 0.17, b.loop_travel_m = 0.02;
  raw.reset(a);
  const DeviceJoints passed = raw.filter(b, kTickS);
  EXPECT_EQ(passed.yaw_rad, b.yaw_rad);
  EXPECT_EQ(passed.insertion_m, b.insertion_m);
  smooth.reset(b);
  const DeviceJoints held = smooth.filter(b, kTickS);
  EXPECT_EQ(held.insertion_m, b.insertion_m);
  EXPECT_EQ(held.loop_travel_m, b.loop_travel_m);
}

}  // namespace
}  // namespace resecto
