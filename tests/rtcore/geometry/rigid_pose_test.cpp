// RigidPose: composition, inverse and the inverse map checked against applying the parts one after
// another; the coordinate-axis rotations against Rodrigues' formula; the row-major text layout.
#include "rtcore/geometry/rigid_pose.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include <glm/matrix.hpp>

namespace resecto {
namespace {

constexpr double kPi = 3.14159265358979323846;

RigidPose random_pose(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  const Vec3 axis = glm::normalize(Vec3(unit(rng), unit(rng), unit(rng)));
  RigidPose pose;
  pose.rotation = axis_angle_rotation(axis, kPi * unit(rng));
  pose.translation = Vec3(unit(rng), unit(rng), unit(rng)) * 0.1;
  return pose;
}

void expect_near(const Vec3& a, const Vec3& b, double tolerance) {
  EXPECT_NEAR(a.x, b.x, tolerance);
  EXPECT_NEAR(a.y, b.y, tolerance);
  EXPECT_NEAR(a.z, b.z, tolerance);
}

TEST(RigidPose, ComposeAppliesInnerThenOuter) {
  std::mt19937_64 rng(1);
  for (int trial = 0; trial < 100; ++trial) {
    const RigidPose outer = random_pose(rng), inner = random_pose(rng);
    const Vec3 p(0.01 * trial, -0.02, 0.03);
    expect_near(compose(outer, inner).apply_point(p), outer.apply_point(inner.apply_point(p)), 1e-15);
    expect_near(compose(outer, inner).apply_vector(p), outer.apply_vector(inner.apply_vector(p)), 1e-15);
  }
}

TEST(RigidPose, InverseUndoesThePose) {
  std::mt19937_64 rng(2);
  for (int trial = 0; trial < 100; ++trial) {
    const RigidPose pose = random_pose(rng);
    const Vec3 p(0.05, 0.01 * trial, -0.07);
    expect_near(inverse(pose).apply_point(pose.apply_point(p)), p, 1e-15);
    expect_near(pose.inverse_apply_point(pose.apply_point(p)), p, 1e-15);
    // The two forms of the inverse map agree exactly: both are R^T (x - t) summed in one order.
    const Vec3 world = pose.apply_point(p);
    const Vec3 by_inverse = glm::transpose(pose.rotation) * (world - pose.translation);
    EXPECT_EQ(pose.inverse_apply_point(world), by_inverse);
    EXPECT_LT(orthonormality_error(compose(inverse(pose), pose).rotation), 1e-14);
  }
}

TEST(RigidPose, AxisRotationsMatchRodrigues) {
  for (double angle : {-2.5, -0.3, 0.0, 0.7, 1.9, 3.1}) {
    const glm::dmat3 about[3] = {rotation_about_x(angle), rotation_about_y(angle), rotation_about_z(angle)};
    const Vec3 axes[3] = {Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1)};
    for (int a = 0; a < 3; ++a) {
      const glm::dmat3 expected = axis_angle_rotation(axes[a], angle);
      for (int c = 0; c < 3; ++c) {
        for (int r = 0; r < 3; ++r) EXPECT_NEAR(about[a][c][r], expected[c][r], 1e-15) << "axis " << a << " angle " << angle;
      }
      EXPECT_LT(orthonormality_error(about[a]), 1e-14);
      EXPECT_NEAR(glm::determinant(about[a]), 1.0, 1e-14);
    }
  }
  // Right-handed: a quarter turn about z takes x to y.
  expect_near(rotation_about_z(kPi / 2) * Vec3(1, 0, 0), Vec3(0, 1, 0), 1e-16);
}

TEST(RigidPose, RowMajorLayoutMatchesThePosesFile) {
  RigidPose pose;
  pose.rotation = axis_angle_rotation(Vec3(0, 0, 1), kPi / 2);  // x -> y
  pose.translation = Vec3(1, 2, 3);
  const auto m = to_row_major_3x4(pose);
  const double expected[12] = {0, -1, 0, 1, 1, 0, 0, 2, 0, 0, 1, 3};
  for (int i = 0; i < 12; ++i) EXPECT_NEAR(m[static_cast<std::size_t>(i)], expected[i], 1e-16) << i;
  const RigidPose back = from_row_major_3x4(m);
  EXPECT_EQ(back.rotation, pose.rotation);
  EXPECT_EQ(back.translation, pose.translation);
}

TEST(RigidPose, OrthonormalityErrorSeesAStretch) {
  glm::dmat3 stretched(1.0);
  stretched[1][1] = 1.001;
  EXPECT_NEAR(orthonormality_error(stretched), 1.001 * 1.001 - 1.0, 1e-15);
  EXPECT_EQ(orthonormality_error(glm::dmat3(1.0)), 0.0);
}

}  // namespace
}  // namespace resecto
