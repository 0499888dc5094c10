// RigidPose: a rotation and a translation, the core's one rigid placement. The kinematics hand the
// sheath's and loop's placement to the core in it, the collision query and the contact response
// place the tool with it, and the registration of the device frame to the world is one.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>

#include <glm/mat3x3.hpp>
#include <glm/matrix.hpp>

#include "rtcore/geometry/vec3.h"

namespace resecto {

/// x_world = rotation * x_local + translation. Metres. The rotation is a glm matrix, column-major:
/// `rotation[c][r]` is row r, column c (use from_row_major_3x4 / to_row_major_3x4 for row-major text).
struct RigidPose {
  glm::dmat3 rotation{1.0};
  Vec3 translation{0.0};

  /// Maps a point of the local frame into the parent frame. The one way a tool point reaches the
  /// world: every caller (collision query, brute force, contact) rounds alike.
  Vec3 apply_point(const Vec3& p) const { return rotation * p + translation; }
  /// Maps a direction (no translation).
  Vec3 apply_vector(const Vec3& v) const { return rotation * v; }
  /// Maps a parent-frame point into the local frame, for an orthonormal rotation: R^T (p - t).
  Vec3 inverse_apply_point(const Vec3& p) const { return (p - translation) * rotation; }
};

/// `outer` after `inner`: compose(outer, inner).apply_point(p) == outer.apply_point(inner.apply_point(p)).
RigidPose compose(const RigidPose& outer, const RigidPose& inner);

/// The inverse transform (rotation transposed).
RigidPose inverse(const RigidPose& pose);

/// How far a registration may place the device: each coordinate of its translation (and of the
/// gimbal's pivot) within this many metres of the origin, a metre either way being generous beside a
/// patient. Calibration files and recordings' headers are held to it.
inline constexpr double kRegistrationReachM = 1.0;

/// Whether `m` is a proper rotation: R^T R = I to `tolerance` in every entry, and det R > 0 (no
/// scale, shear or mirror). Registrations from files and recordings are held to it.
/// Inline, so the device's calibration reader (which links only rtcore's base) holds its files to it too.
inline bool is_proper_rotation(const glm::dmat3& m, double tolerance = 1e-6) {
  const glm::dmat3 gram = glm::transpose(m) * m;
  double worst = 0.0;
  for (int c = 0; c < 3; ++c) {
    for (int r = 0; r < 3; ++r) worst = std::max(worst, std::abs(gram[c][r] - (r == c ? 1.0 : 0.0)));
  }
  return worst <= tolerance && glm::determinant(m) > 0.0;  // a NaN fails both
}

/// Rotation about a unit axis by `angle_rad`, right-handed.
glm::dmat3 axis_angle_rotation(const Vec3& unit_axis, double angle_rad);
/// Rotations about the coordinate axes by `angle_rad`, right-handed (exact zeros and ones).
glm::dmat3 rotation_about_x(double angle_rad);
glm::dmat3 rotation_about_y(double angle_rad);
glm::dmat3 rotation_about_z(double angle_rad);

/// Row-major 3x4 `[R|t]`, the 12 numbers of the `collide` poses file (translation in metres here).
std::array<double, 12> to_row_major_3x4(const RigidPose& pose);
/// The pose of row-major 3x4 `[R|t]` numbers (the inverse of to_row_major_3x4).
RigidPose from_row_major_3x4(const std::array<double, 12>& m);

/// Largest |R^T R - I| entry: how far `rotation` is from orthonormal.
double orthonormality_error(const glm::dmat3& rotation);

}  // namespace resecto
