// Poses of the resectoscope in the gland's urethral channel, shared by the collision tests and the
// collision benchmark: random poses in the channel, a sweep along it, and the sheath pressed into
// the channel wall (independent poses and a 60 Hz trajectory). Metres, for the gland of
// generate_prostate's default shape and the tool of generate_resectoscope.
#pragma once

#include <random>
#include <vector>

#include "rtcore/geometry/rigid_pose.h"

namespace resecto {

/// Turns the tool's +z by small tilts about x and y after a roll about z (R = Ry * (Rx * Rz)), then
/// places its tip at `tip`.
RigidPose tilted_pose(double tilt_x_rad, double tilt_y_rad, double roll_rad, const Vec3& tip);

/// A random pose in the channel: the tip somewhere along it (5-45 mm), off-axis by up to 3 mm,
/// tilted up to 4 degrees about x and y, any roll.
RigidPose random_channel_pose(std::mt19937_64& rng);

/// Frame `frame` of a sweep at 60 Hz: the tip advancing along the channel 0.2 mm a frame, off-axis
/// toward a slowly turning side (pressed into the wall), rolling and tilting a little; `phase`
/// picks one of a family of sweeps.
RigidPose channel_sweep_pose(int frame, double phase);

/// The sheath along the channel, its tip at depth `z_m`, pushed sideways toward angle `theta` by
/// `offset_m`, tilted by `tilt_rad` about the axis across the push after a roll about z: the sheath
/// (8.67 mm) is wider than the lobes leave the lumen, so it lies against the wall along its length
/// and the loop presses into it.
RigidPose pressing_pose(double z_m, double theta, double offset_m, double tilt_rad, double roll_rad);

/// 24 independent pressing poses from 12 to 40 mm deep (seeded: the same every run).
std::vector<RigidPose> pressing_poses();

/// A 60 Hz trajectory of 2 s: the sheath pressed 0.8-1.6 mm into the channel wall, advancing 10 mm/s
/// along it while swinging between sides, and the loop swept through the lobe by rolling the tool.
/// Consecutive frames move the tool's points 0.2-0.4 mm (its far end included): what
/// Collider::collide_sequence() reuses.
std::vector<RigidPose> pressing_trajectory();

}  // namespace resecto
