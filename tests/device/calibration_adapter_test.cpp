// The calibration file's registration and encoder resolutions, as the link and kinematics use them.
#include "device/link/calibration_adapter.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <numbers>
#include <string>

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

TEST(CalibrationAdapter, TipRunsFromApexToBladderNeckInsideTheGeneratedLumen) {
  const ProstateModel prostate = generate_prostate(1296);
  const GimbalGeometry geometry = gimbal_geometry_from(device::default_calibration());
  const auto landmark = [&](const std::string& name) {
    for (const Landmark& l : prostate.landmarks) {
      if (l.name == name) return l.position;
    }
    ADD_FAILURE() << "no landmark " << name;
    return Vec3(0.0);
  };
  const Vec3 apex = landmark("apex");
  const Vec3 neck = landmark("bladder_neck");
  DeviceJoints joints;
  for (int step = 0; step <= 100; ++step) {
    const double fraction = step / 100.0;
    const Vec3 target = apex + (neck - apex) * fraction;
    joints.insertion_m = 0.150 + target.z;  // the sheath reading that should put the tip there
    const Vec3 tip = sheath_tip_world(joints, geometry);
    ASSERT_LT(length(tip - target), 1e-12) << "step " << step;
    // Inside the lumen: no surface vertex closer than the narrowest bulge leaves (about 2.9 mm).
    double nearest = 1.0;
    for (const Vec3& p : prostate.surface.positions) nearest = std::min(nearest, length(p - tip));
    ASSERT_GT(nearest, 0.0025) << "step " << step << " tip z " << tip.z;
  }
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
