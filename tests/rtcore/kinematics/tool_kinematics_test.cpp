// Forward kinematics: known joints give known poses, poses are rigid, the registration transform is
// applied last, and zero yaw/pitch keeps the tip on the channel axis over the insertion range.
#include "rtcore/kinematics/tool_kinematics.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

namespace resecto {
namespace {

constexpr double kTolerance = 1e-12;
constexpr double kPi = std::numbers::pi;

void expect_near(const Vec3& actual, const Vec3& expected, double tolerance = kTolerance) {
  EXPECT_NEAR(actual.x, expected.x, tolerance);
  EXPECT_NEAR(actual.y, expected.y, tolerance);
  EXPECT_NEAR(actual.z, expected.z, tolerance);
}

TEST(ToolKinematics, ZeroJointsPutTheTipOnThePivotAxis) {
  const GimbalGeometry geometry;
  DeviceJoints joints;
  joints.insertion_m = 0.170;
  const ToolPoses poses = tool_poses(joints, geometry);
  expect_near(poses.sheath.translation, Vec3(0.0, 0.0, 0.020));
  expect_near(poses.sheath.apply_vector(Vec3(0, 0, 1)), Vec3(0, 0, 1));
  expect_near(poses.sheath.apply_vector(Vec3(0, -1, 0)), Vec3(0, -1, 0));  // wire still hangs down
  expect_near(poses.loop.translation, poses.sheath.translation);           // zero travel
}

TEST(ToolKinematics, YawSwingsTheTipTowardPlusX) {
  GimbalGeometry geometry;
  geometry.pivot_m = Vec3(0.0);
  DeviceJoints joints;
  joints.yaw_rad = kPi / 2;
  joints.insertion_m = 0.1;
  expect_near(sheath_tip_world(joints, geometry), Vec3(0.1, 0.0, 0.0));
  joints.yaw_rad = kPi / 6;
  expect_near(sheath_tip_world(joints, geometry), Vec3(0.05, 0.0, 0.1 * std::sqrt(3.0) / 2));
}

TEST(ToolKinematics, PitchLiftsTheTipTowardPlusY) {
  GimbalGeometry geometry;
  geometry.pivot_m = Vec3(0.0);
  DeviceJoints joints;
  joints.pitch_rad = kPi / 2;
  joints.insertion_m = 0.1;
  expect_near(sheath_tip_world(joints, geometry), Vec3(0.0, 0.1, 0.0));
  joints.pitch_rad = -kPi / 4;
  expect_near(sheath_tip_world(joints, geometry), Vec3(0.0, -0.1 / std::sqrt(2.0), 0.1 / std::sqrt(2.0)));
}

TEST(ToolKinematics, RollTurnsTheLoopAboutTheAxisOnly) {
  const GimbalGeometry geometry;
  DeviceJoints joints;
  joints.insertion_m = 0.16;
  joints.roll_rad = kPi / 2;
  const ToolPoses poses = tool_poses(joints, geometry);
  expect_near(poses.sheath.translation, Vec3(0.0, 0.0, 0.010));                // tip unmoved
  expect_near(poses.sheath.apply_vector(Vec3(0, -1, 0)), Vec3(1, 0, 0));        // wire now at +x
  expect_near(poses.sheath.apply_vector(Vec3(0, 0, 1)), Vec3(0, 0, 1));
}

TEST(ToolKinematics, YawThenPitchOrderIsRingCarriesDisk) {
  // With yaw 90 deg the disk's axis is world -z... pitch then lifts toward +y from the yawed axis.
  GimbalGeometry geometry;
  geometry.pivot_m = Vec3(0.0);
  DeviceJoints joints;
  joints.yaw_rad = kPi / 2;
  joints.pitch_rad = kPi / 4;
  joints.insertion_m = 1.0;
  const double h = 1.0 / std::sqrt(2.0);
  expect_near(sheath_tip_world(joints, geometry), Vec3(h, h, 0.0));
}

TEST(ToolKinematics, LoopTravelsAlongTheTiltedAxis) {
  const GimbalGeometry geometry;
  DeviceJoints joints;
  joints.yaw_rad = 0.2;
  joints.pitch_rad = -0.1;
  joints.roll_rad = 1.3;
  joints.insertion_m = 0.18;
  joints.loop_travel_m = 0.036;
  const ToolPoses poses = tool_poses(joints, geometry);
  const Vec3 axis = poses.sheath.apply_vector(Vec3(0, 0, 1));
  expect_near(poses.loop.translation - poses.sheath.translation, axis * 0.036);
  // The loop's local point (0,0,0.036) relative to the sheath equals the loop's origin.
  expect_near(poses.sheath.apply_point(Vec3(0, 0, 0.036)), poses.loop.apply_point(Vec3(0.0)));
  EXPECT_LT(orthonormality_error(poses.sheath.rotation), 1e-14);
  EXPECT_NEAR(glm::determinant(poses.sheath.rotation), 1.0, 1e-14);
  // The tip stays on the sphere of radius `insertion` about the pivot, and the axis goes through it.
  EXPECT_NEAR(length(poses.sheath.translation - geometry.pivot_m), 0.18, 1e-14);
  expect_near(poses.sheath.apply_point(Vec3(0, 0, -0.18)), geometry.pivot_m);
}

TEST(ToolKinematics, RegistrationIsAppliedAfterTheGimbal) {
  GimbalGeometry geometry;
  geometry.device_to_world.rotation = axis_angle_rotation(Vec3(0, 0, 1), kPi / 2);
  geometry.device_to_world.translation = Vec3(0.01, -0.02, 0.03);
  DeviceJoints joints;
  joints.yaw_rad = 0.3;
  joints.pitch_rad = 0.2;
  joints.roll_rad = -0.4;
  joints.insertion_m = 0.17;
  joints.loop_travel_m = 0.01;
  const ToolPoses registered = tool_poses(joints, geometry);
  const ToolPoses in_device = tool_poses(joints, GimbalGeometry{geometry.pivot_m, RigidPose{}});
  const Vec3 local(0.001, -0.002, 0.003);
  expect_near(registered.sheath.apply_point(local),
              geometry.device_to_world.apply_point(in_device.sheath.apply_point(local)));
  expect_near(registered.loop.apply_point(local),
              geometry.device_to_world.apply_point(in_device.loop.apply_point(local)));
  // And inverse() undoes it.
  expect_near(inverse(registered.sheath).apply_point(registered.sheath.apply_point(local)), local);
}

TEST(ToolKinematics, TipFollowsTheChannelAxisOverTheInsertionRange) {
  // Procedural prostate: channel axis = world z, apex at z=0, bladder neck at z=44 mm. With the
  // default pivot at z=-150 mm, insertion 150..194 mm must run the tip along the axis, 0.1 mm steps.
  const GimbalGeometry geometry;
  DeviceJoints joints;
  joints.roll_rad = 0.7;  // roll must not move the tip off the axis
  for (int step = 0; step <= 440; ++step) {
    joints.insertion_m = 0.150 + step * 1e-4;
    const Vec3 tip = sheath_tip_world(joints, geometry);
    ASSERT_NEAR(std::hypot(tip.x, tip.y), 0.0, 1e-15) << "insertion step " << step;
    ASSERT_NEAR(tip.z, step * 1e-4, 1e-12) << "insertion step " << step;
  }
}

}  // namespace
}  // namespace resecto
