// RigidPose: a rotation and a translation, the form in which the device's kinematics hand the
// sheath's and loop's placement to the core (and the registration of the device frame to the world).
#pragma once

#include <array>

#include <glm/mat3x3.hpp>

#include "rtcore/geometry/vec3.h"

namespace resecto {

/// x_world = rotation * x_local + translation. Metres.
struct RigidPose {
  glm::dmat3 rotation{1.0};
  Vec3 translation{0.0};

  /// Maps a point of the local frame into the parent frame.
  Vec3 apply_point(const Vec3& p) const { return rotation * p + translation; }
  /// Maps a direction (no translation).
  Vec3 apply_vector(const Vec3& v) const { return rotation * v; }
};

/// `outer` after `inner`: (outer * inner).apply_point(p) == outer.apply_point(inner.apply_point(p)).
RigidPose compose(const RigidPose& outer, const RigidPose& inner);

/// The inverse transform (rotation transposed).
RigidPose inverse(const RigidPose& pose);

/// Rotation about a unit axis by `angle_rad`, right-handed.
glm::dmat3 axis_angle_rotation(const Vec3& unit_axis, double angle_rad);

/// Row-major 3x4 `[R|t]`, the 12 numbers of the `collide` poses file (translation in metres here).
std::array<double, 12> to_row_major_3x4(const RigidPose& pose);

/// Largest |R^T R - I| entry: how far `rotation` is from orthonormal.
double orthonormality_error(const glm::dmat3& rotation);

}  // namespace resecto
