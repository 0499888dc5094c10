// Forward kinematics of the 5-DOF resectoscope device: the disk-ring gimbal's yaw and pitch about a
// fixed pivot, the sheath's roll about its own axis and insertion along it, and the loop's travel out
// of the tip, mapped to the sheath's and the loop's rigid poses in the world frame.
//
// Frames. Tool frame (rtcore/anatomy/resectoscope.h): sheath axis +z, tip at the origin, shaft toward
// -z, loop wire below the axis (-y). Device frame: the gimbal's; at zero yaw and pitch the sheath
// axis is device +z and the tip sits `insertion_m` in front of the pivot. The registration transform
// (from the calibration file) maps the device frame to the world. With the identity registration and
// the default pivot (0, 0, -150) mm, zero yaw/pitch puts the sheath on the procedural prostate's
// channel axis (world z), and insertions of 150..194 mm carry the tip from the apex to the bladder neck.
#pragma once

#include "rtcore/geometry/rigid_pose.h"
#include "rtcore/geometry/vec3.h"

namespace resecto {

/// The five measured degrees of freedom, in SI units.
struct DeviceJoints {
  double yaw_rad = 0.0;        ///< ring about device +y; positive swings the tip toward +x
  double pitch_rad = 0.0;      ///< disk about the yawed x axis; positive lifts the tip toward +y
  double roll_rad = 0.0;       ///< sheath about its own axis, right-handed about tool +z
  double insertion_m = 0.0;    ///< pivot-to-tip distance along the sheath axis
  double loop_travel_m = 0.0;  ///< loop out of the sheath tip along the axis (0 .. 0.036)
};

/// Where the gimbal is and how the device frame sits in the world.
struct GimbalGeometry {
  Vec3 pivot_m{0.0, 0.0, -0.150};  ///< the gimbal's pivot in the device frame
  RigidPose device_to_world;       ///< registration; identity: device frame == world frame
};

/// Rigid poses of the two tool parts: tool frame -> world frame.
struct ToolPoses {
  RigidPose sheath;  ///< places the sheath mesh (tip at the tool origin)
  RigidPose loop;    ///< places the loop mesh generated at zero travel
};

/// Orientation of the sheath in the device frame: yaw, then pitch, then roll (R = Ry * Rx(-pitch) * Rz).
glm::dmat3 gimbal_rotation(const DeviceJoints& joints);

/// Sheath and loop poses in the world for the given joints.
ToolPoses tool_poses(const DeviceJoints& joints, const GimbalGeometry& geometry);

/// The sheath tip in the world (the sheath pose's translation).
Vec3 sheath_tip_world(const DeviceJoints& joints, const GimbalGeometry& geometry);

}  // namespace resecto
