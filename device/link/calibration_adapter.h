// From the calibration file (device_calibration, millimetres and row-major matrices) to the forms the
// link and the kinematics use: encoder resolutions for converting counts, and the registration of the
// device frame (origin at the gimbal pivot) to the world.
#pragma once

#include "device/calibration/calibration.h"
#include "rtcore/kinematics/tool_kinematics.h"
#include "device/link/report_decoder.h"

namespace resecto {

/// Encoder counts per revolution; encoder zeros at power-up; sheath reading = pivot-to-tip distance.
JointCalibration joint_calibration_from(const device::Calibration& calibration);

/// The pivot at the device origin and the file's registration transform (mm -> m).
GimbalGeometry gimbal_geometry_from(const device::Calibration& calibration);

}  // namespace resecto
