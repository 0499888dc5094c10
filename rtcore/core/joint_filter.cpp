// One Euro filter: an exponential smoother whose cut-off follows the smoothed speed.
#include "rtcore/core/joint_filter.h"

#include <cmath>
#include <numbers>

namespace resecto {
namespace {

/// The smoothing factor of a first-order low-pass at `cutoff_hz` sampled every `dt_s`.
double smoothing(double cutoff_hz, double dt_s) {
  const double tau_s = 1.0 / (2.0 * std::numbers::pi * cutoff_hz);
  return 1.0 / (1.0 + tau_s / dt_s);
}

}  // namespace

double OneEuroFilter::filter(double reading, double dt_s, double min_cutoff_hz, double derivative_cutoff_hz, double beta) {
  const double raw_speed = (reading - value_) / dt_s;
  speed_ += smoothing(derivative_cutoff_hz, dt_s) * (raw_speed - speed_);
  const double cutoff_hz = min_cutoff_hz + beta * std::abs(speed_);
  value_ += smoothing(cutoff_hz, dt_s) * (reading - value_);
  return value_;
}

void JointFilter::reset(const DeviceJoints& joints) {
  yaw_.reset(joints.yaw_rad);
  pitch_.reset(joints.pitch_rad);
  roll_.reset(joints.roll_rad);
  insertion_.reset(joints.insertion_m);
  loop_.reset(joints.loop_travel_m);
}

DeviceJoints JointFilter::filter(const DeviceJoints& reading, double dt_s) {
  if (!settings_.enabled) return reading;
  const JointFilterSettings& s = settings_;
  DeviceJoints out;
  out.yaw_rad = yaw_.filter(reading.yaw_rad, dt_s, s.min_cutoff_hz, s.derivative_cutoff_hz, s.angular_beta_s_per_rad);
  out.pitch_rad = pitch_.filter(reading.pitch_rad, dt_s, s.min_cutoff_hz, s.derivative_cutoff_hz, s.angular_beta_s_per_rad);
  out.roll_rad = roll_.filter(reading.roll_rad, dt_s, s.min_cutoff_hz, s.derivative_cutoff_hz, s.angular_beta_s_per_rad);
  out.insertion_m = insertion_.filter(reading.insertion_m, dt_s, s.min_cutoff_hz, s.derivative_cutoff_hz, s.linear_beta_per_m);
  out.loop_travel_m = loop_.filter(reading.loop_travel_m, dt_s, s.min_cutoff_hz, s.derivative_cutoff_hz, s.linear_beta_per_m);
  return out;
}

}  // namespace resecto
