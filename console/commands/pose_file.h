// The tool-pose file of `resecto collide`: one rigid transform a line, 12 numbers, row-major [R|t].
#pragma once

#include <string>
#include <vector>

#include "rtcore/base/result.h"
#include "rtcore/collision/collide.h"

namespace resecto::cli {

/// Largest translation component read, in the file's units (a kilometre of millimetres).
inline constexpr double kMaxPoseTranslation = 1e6;

/// Parses pose text: blank lines and '#' comments skipped; every rotation orthonormal to 1e-4 with
/// determinant +1 (a mirror is not a rigid motion); errors name file:line.
Result<std::vector<RigidPose>> parse_poses(const std::string& text, const std::string& source);

}  // namespace resecto::cli
