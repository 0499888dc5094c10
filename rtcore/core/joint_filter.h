// The device's readings smoothed before they place the tool: a One Euro filter per joint (Casiez,
// Roussel and Vogel, CHI 2012), the usual filter for hand-held input. The emulated LP3500 reads the
// sheath's potentiometer with 0.18 mm RMS noise and its encoders in 1.5 mrad counts (0.26 mm at the
// sheath's tip); unfiltered, the tool's tip trembles by tenths of a millimetre every tick, which
// shakes the endoscopic view and hammers the tissue through the contact's damping. The filter's
// cut-off rises with speed, so a still hand is smoothed hard and a fast one is followed closely.
#pragma once

#include "rtcore/kinematics/tool_kinematics.h"

namespace resecto {

struct JointFilterSettings {
  double min_cutoff_hz = 1.0;         ///< cut-off of a still joint
  double derivative_cutoff_hz = 3.0;  ///< smoothing of the speed estimate that raises the cut-off
  /// How fast the cut-off rises with speed: +10 Hz at 50 mm/s (sheath and loop) and at 0.3 rad/s
  /// (yaw, pitch: the tip moves ~50 mm/s; roll: the loop's wire ~5 mm/s).
  double linear_beta_per_m = 200.0;
  double angular_beta_s_per_rad = 33.0;
  bool enabled = true;
};

/// One joint's One Euro filter.
class OneEuroFilter {
 public:
  void reset(double value) {
    value_ = value;
    speed_ = 0.0;
  }
  /// Filters a reading `dt_s` after the previous one (dt_s > 0).
  double filter(double reading, double dt_s, double min_cutoff_hz, double derivative_cutoff_hz, double beta);
  double value() const { return value_; }

 private:
  double value_ = 0.0;
  double speed_ = 0.0;
};

/// The five joints' filters. Deterministic: the output depends only on the readings and the step.
class JointFilter {
 public:
  explicit JointFilter(const JointFilterSettings& settings = {}) : settings_(settings) {}
  /// Starts from `joints` (no history): the tool appears where the device is.
  void reset(const DeviceJoints& joints);
  /// The smoothed joints after a reading `dt_s` after the previous one.
  DeviceJoints filter(const DeviceJoints& reading, double dt_s);

 private:
  JointFilterSettings settings_;
  OneEuroFilter yaw_, pitch_, roll_, insertion_, loop_;
};

}  // namespace resecto
