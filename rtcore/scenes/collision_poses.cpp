// The collision scenes' tool poses. Every rotation is built from rigid_pose.h's rotations, so a
// pose is the same bits in the tests, the benchmark and the pose files it writes.
#include "rtcore/scenes/collision_poses.h"

#include <cmath>

namespace resecto {

RigidPose tilted_pose(double tilt_x_rad, double tilt_y_rad, double roll_rad, const Vec3& tip) {
  RigidPose pose;
  pose.rotation = rotation_about_y(tilt_y_rad) * (rotation_about_x(tilt_x_rad) * rotation_about_z(roll_rad));
  pose.translation = tip;
  return pose;
}

RigidPose random_channel_pose(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const double angle = 2.0 * M_PI * unit(rng);
  const double offset = 0.003 * unit(rng);
  const Vec3 tip{offset * std::cos(angle), offset * std::sin(angle), 0.005 + 0.040 * unit(rng)};
  // One draw a statement (in the order GCC gave them as arguments): the same poses on every compiler.
  const double roll = 2.0 * M_PI * unit(rng);
  const double tilt_y = 0.14 * (unit(rng) - 0.5);
  const double tilt_x = 0.14 * (unit(rng) - 0.5);
  return tilted_pose(tilt_x, tilt_y, roll, tip);
}

RigidPose channel_sweep_pose(int frame, double phase) {
  const double t = frame / 60.0;
  const double angle = phase + 0.8 * std::sin(1.3 * t);
  const double offset = 0.0022 + 0.0008 * std::sin(2.1 * t + phase);
  const Vec3 tip{offset * std::cos(angle), offset * std::sin(angle), 0.010 + 0.012 * t};
  return tilted_pose(0.03 * std::sin(0.7 * t + phase), 0.03 * std::cos(0.9 * t), phase + 0.6 * std::sin(2.5 * t), tip);
}

RigidPose pressing_pose(double z_m, double theta, double offset_m, double tilt_rad, double roll_rad) {
  const Vec3 axis{-std::sin(theta), std::cos(theta), 0.0};
  RigidPose pose;
  pose.rotation = axis_angle_rotation(axis, tilt_rad) * rotation_about_z(roll_rad);
  pose.translation = Vec3{offset_m * std::cos(theta), offset_m * std::sin(theta), z_m};
  return pose;
}

std::vector<RigidPose> pressing_poses() {
  std::vector<RigidPose> poses;
  std::mt19937_64 rng(2006);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  // One draw a statement, so every compiler draws in the same order (the order GCC gave these
  // draws when they were a call's arguments, which keeps the published benchmark poses).
  for (int i = 0; i < 24; ++i) {
    const double z = 0.012 + 0.028 * i / 23.0;
    const double roll = -M_PI / 2 + 0.6 * (unit(rng) - 0.5);
    const double tilt = 0.03 * (unit(rng) - 0.5);
    const double offset = 0.0005 + 0.0015 * unit(rng);
    const double theta = 2.0 * M_PI * unit(rng);
    poses.push_back(pressing_pose(z, theta, offset, tilt, roll));
  }
  return poses;
}

std::vector<RigidPose> pressing_trajectory() {
  std::vector<RigidPose> poses;
  constexpr int kFrames = 120;
  for (int f = 0; f < kFrames; ++f) {
    const double t = f / 60.0;
    poses.push_back(pressing_pose(0.015 + 0.010 * t, 0.6 + 0.25 * std::sin(1.5 * t), 0.0012 + 0.0004 * std::sin(2.0 * t),
                                  0.01 * std::sin(t), -M_PI / 2 + 0.5 * std::sin(3.0 * t)));
  }
  return poses;
}

}  // namespace resecto
