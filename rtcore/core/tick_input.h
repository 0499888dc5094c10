// TickInput: what the core latches for one tick, in the core's own terms. The device link converts
// its calibrated samples into it (device/link/tool_input.h), the recorder stores it, and replay feeds
// it back: the core's input type belongs to the core, so nothing in rtcore/ looks up at device/.
#pragma once

#include "rtcore/kinematics/tool_kinematics.h"

namespace resecto {

/// The input latched for one tick.
struct TickInput {
  DeviceJoints joints;        ///< calibrated (and unsmoothed: the core filters) joint values
  bool cut = false;           ///< cutting pedal down
  bool coagulate = false;     ///< coagulation pedal down
  bool tool_present = false;  ///< false until the device has reported (the tool stays withdrawn)
};

}  // namespace resecto
