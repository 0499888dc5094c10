// The calibration file's registration and encoder resolutions, as the link and kinematics use them.
#include "device/link/calibration_adapter.h"

#include <gtest/gtest.h>

#include <numbers>

#include "rtcore/anatomy/prostate.h"

namespace resecto {
namespace {

TEST(CalibrationAdapter, DefaultCalibrationAimsDownTheProstateChannel) {
  const device::Calibration calibration = device::default_calibration();
  const GimbalGeometry geometry = gimbal_geometry_from(calibration);
  const ProstateShape prostate;
  DeviceJoints joints;
  // Sheath readings 150..194 mm carry the tip from the apex (z = 0) to the bladder neck (z = 44 mm),
  // on the channel axis, and the sheath's body stays inside the lumen's widest radius.
  for (double reading_mm = 150.0; reading_mm <= 150.0 + prostate.length_m * 1e3; reading_mm += 0.5) {
    joints.insertion_m = reading_mm * 1e-3;
    const Vec3 tip = sheath_tip_world(joints, geometry);
    ASSERT_NEAR(tip.x, 0.0, 1e-12);
    ASSERT_NEAR(tip.y, 0.0, 1e-12);
    ASSERT_NEAR(tip.z, (reading_mm - 150.0) * 1e-3, 1e-12);
    ASSERT_LT(std::hypot(tip.x, tip.y), channel_radius_at(prostate, tip.z, 0.0));
  }
  const JointCalibration joint = joint_calibration_from(calibration);
  EXPECT_EQ(joint.encoder_counts_per_rev[0], 4096.0);
}

TEST(CalibrationAdapter, RegistrationRotationIsReadRowMajor) {
  device::Calibration calibration = device::default_calibration();
  // Device x -> world y, device y -> world -x (a quarter turn about z), pivot at (10, 20, 30) mm.
  calibration.rotation = {{{0, -1, 0}, {1, 0, 0}, {0, 0, 1}}};
  calibration.translation_mm = {10.0, 20.0, 30.0};
  calibration.encoder_counts_per_revolution = {2000, 4096, 1024};
  const GimbalGeometry geometry = gimbal_geometry_from(calibration);
  DeviceJoints joints;
  joints.yaw_rad = std::numbers::pi / 2;  // tip toward device +x
  joints.insertion_m = 0.1;
  const Vec3 tip = sheath_tip_world(joints, geometry);
  EXPECT_NEAR(tip.x, 0.010, 1e-12);
  EXPECT_NEAR(tip.y, 0.120, 1e-12);
  EXPECT_NEAR(tip.z, 0.030, 1e-12);
  EXPECT_EQ(joint_calibration_from(calibration).encoder_counts_per_rev[0], 2000.0);
  EXPECT_EQ(joint_calibration_from(calibration).encoder_counts_per_rev[2], 1024.0);
}

}  // namespace
}  // namespace resecto
