// Rigid pose composition, rotations and conversions to and from row-major text.
#include "rtcore/geometry/rigid_pose.h"

#include <algorithm>
#include <cmath>

#include <glm/matrix.hpp>

namespace resecto {

RigidPose compose(const RigidPose& outer, const RigidPose& inner) {
  RigidPose result;
  result.rotation = outer.rotation * inner.rotation;
  result.translation = outer.rotation * inner.translation + outer.translation;
  return result;
}

RigidPose inverse(const RigidPose& pose) {
  RigidPose result;
  result.rotation = glm::transpose(pose.rotation);
  result.translation = -(result.rotation * pose.translation);
  return result;
}

glm::dmat3 axis_angle_rotation(const Vec3& unit_axis, double angle_rad) {
  const double c = std::cos(angle_rad);
  const double s = std::sin(angle_rad);
  const double t = 1.0 - c;
  const double x = unit_axis.x, y = unit_axis.y, z = unit_axis.z;
  // glm is column-major: m[column][row]. Rodrigues' formula written out.
  glm::dmat3 m;
  m[0] = Vec3(t * x * x + c, t * x * y + s * z, t * x * z - s * y);
  m[1] = Vec3(t * x * y - s * z, t * y * y + c, t * y * z + s * x);
  m[2] = Vec3(t * x * z + s * y, t * y * z - s * x, t * z * z + c);
  return m;
}

glm::dmat3 rotation_about_x(double angle_rad) {
  const double c = std::cos(angle_rad), s = std::sin(angle_rad);
  return glm::dmat3(Vec3(1, 0, 0), Vec3(0, c, s), Vec3(0, -s, c));  // columns
}

glm::dmat3 rotation_about_y(double angle_rad) {
  const double c = std::cos(angle_rad), s = std::sin(angle_rad);
  return glm::dmat3(Vec3(c, 0, -s), Vec3(0, 1, 0), Vec3(s, 0, c));
}

glm::dmat3 rotation_about_z(double angle_rad) {
  const double c = std::cos(angle_rad), s = std::sin(angle_rad);
  return glm::dmat3(Vec3(c, s, 0), Vec3(-s, c, 0), Vec3(0, 0, 1));
}

std::array<double, 12> to_row_major_3x4(const RigidPose& pose) {
  std::array<double, 12> out{};
  for (int row = 0; row < 3; ++row) {
    for (int col = 0; col < 3; ++col) out[static_cast<std::size_t>(row * 4 + col)] = pose.rotation[col][row];
    out[static_cast<std::size_t>(row * 4 + 3)] = pose.translation[row];
  }
  return out;
}

RigidPose from_row_major_3x4(const std::array<double, 12>& m) {
  RigidPose pose;
  for (int row = 0; row < 3; ++row) {
    for (int col = 0; col < 3; ++col) pose.rotation[col][row] = m[static_cast<std::size_t>(row * 4 + col)];
    pose.translation[row] = m[static_cast<std::size_t>(row * 4 + 3)];
  }
  return pose;
}

double orthonormality_error(const glm::dmat3& rotation) {
  const glm::dmat3 product = glm::transpose(rotation) * rotation;
  double worst = 0.0;
  for (int col = 0; col < 3; ++col) {
    for (int row = 0; row < 3; ++row) {
      const double expected = row == col ? 1.0 : 0.0;
      worst = std::max(worst, std::abs(product[col][row] - expected));
    }
  }
  return worst;
}

}  // namespace resecto
