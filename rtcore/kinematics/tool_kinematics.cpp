// Forward kinematics of the disk-ring gimbal: joints -> sheath and loop poses (see the header for frames).
#include "rtcore/kinematics/tool_kinematics.h"

namespace resecto {

glm::dmat3 gimbal_rotation(const DeviceJoints& joints) {
  // The ring (yaw) carries the disk (pitch), which carries the sheath (roll): intrinsic y, x, z.
  // Pitch is negated so that a positive pitch lifts the tip toward +y (anterior) rather than down.
  const glm::dmat3 yaw = axis_angle_rotation(Vec3(0.0, 1.0, 0.0), joints.yaw_rad);
  const glm::dmat3 pitch = axis_angle_rotation(Vec3(1.0, 0.0, 0.0), -joints.pitch_rad);
  const glm::dmat3 roll = axis_angle_rotation(Vec3(0.0, 0.0, 1.0), joints.roll_rad);
  return yaw * pitch * roll;
}

ToolPoses tool_poses(const DeviceJoints& joints, const GimbalGeometry& geometry) {
  RigidPose sheath_in_device;
  sheath_in_device.rotation = gimbal_rotation(joints);
  const Vec3 axis = sheath_in_device.rotation * Vec3(0.0, 0.0, 1.0);
  sheath_in_device.translation = geometry.pivot_m + axis * joints.insertion_m;

  // The loop slides along the sheath's axis and turns with it.
  RigidPose loop_in_device = sheath_in_device;
  loop_in_device.translation = sheath_in_device.translation + axis * joints.loop_travel_m;

  ToolPoses poses;
  poses.sheath = compose(geometry.device_to_world, sheath_in_device);
  poses.loop = compose(geometry.device_to_world, loop_in_device);
  return poses;
}

Vec3 sheath_tip_world(const DeviceJoints& joints, const GimbalGeometry& geometry) {
  return tool_poses(joints, geometry).sheath.translation;
}

}  // namespace resecto
