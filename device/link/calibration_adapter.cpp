// Conversion of the calibration file's contents for the link and the kinematics.
#include "device/link/calibration_adapter.h"

#include "rtcore/base/units.h"

namespace resecto {

JointCalibration joint_calibration_from(const device::Calibration& calibration) {
  JointCalibration joints;
  for (std::size_t axis = 0; axis < 3; ++axis) {
    joints.encoder_counts_per_rev[axis] = static_cast<double>(calibration.encoder_counts_per_revolution[axis]);
  }
  return joints;
}

GimbalGeometry gimbal_geometry_from(const device::Calibration& calibration) {
  GimbalGeometry geometry;
  geometry.pivot_m = Vec3(0.0);
  for (int row = 0; row < 3; ++row) {
    for (int col = 0; col < 3; ++col) {
      // The file is row-major; glm indexes [column][row].
      geometry.device_to_world.rotation[col][row] =
          calibration.rotation[static_cast<std::size_t>(row)][static_cast<std::size_t>(col)];
    }
    geometry.device_to_world.translation[row] = units::mm_to_m(calibration.translation_mm[static_cast<std::size_t>(row)]);
  }
  return geometry;
}

}  // namespace resecto
