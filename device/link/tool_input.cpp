// The per-tick latch of device samples with freeze-on-disconnect and rate-limited re-engagement.
#include "device/link/tool_input.h"

#include <algorithm>
#include <cmath>

namespace resecto {
namespace {

// Moves `value` toward `target` by at most `step`; true when it got there.
bool approach(double& value, double target, double step) {
  const double difference = target - value;
  if (std::abs(difference) <= step) {
    value = target;
    return true;
  }
  value += difference > 0 ? step : -step;
  return false;
}

}  // namespace

void ToolInput::latch(SpscRing<DeviceSample>& ring, double tick_s) {
  DeviceSample entry;
  // Entries are applied in ring order, which is the link's order: a disconnect between two samples
  // is seen between them.
  while (ring.try_pop(entry)) {
    switch (entry.event) {
      case LinkEvent::kDisconnected:
        ++disconnections_seen_;
        have_target_ = false;
        if (state_ != ToolInputState::kNoDevice) state_ = ToolInputState::kFrozen;
        break;
      case LinkEvent::kConnected:
        have_target_ = false;
        if (state_ == ToolInputState::kFrozen || state_ == ToolInputState::kTracking) {
          state_ = ToolInputState::kReengaging;
        }
        break;
      case LinkEvent::kSample:
        target_ = entry.joints;
        have_target_ = true;
        pedals_ = entry.pedals;
        last_sequence_ = entry.sequence;
        last_device_time_us_ = entry.device_time_us;
        ++samples_latched_;
        if (state_ == ToolInputState::kNoDevice || state_ == ToolInputState::kTracking) {
          // Tracking follows every reading at once, so a disconnect later in this same tick freezes
          // the tool at the last reading before it. The first reading places the tool: there is no
          // earlier pose to jump from.
          joints_ = target_;
          state_ = ToolInputState::kTracking;
        } else if (state_ == ToolInputState::kFrozen) {
          state_ = ToolInputState::kReengaging;  // a sample without a kConnected still re-engages
        }
        break;
    }
  }
  if (have_target_ && state_ == ToolInputState::kReengaging) {
    const double angle_step = limits_.max_angular_speed_rad_s * tick_s;
    const double linear_step = limits_.max_linear_speed_m_s * tick_s;
    bool done = approach(joints_.yaw_rad, target_.yaw_rad, angle_step);
    done = approach(joints_.pitch_rad, target_.pitch_rad, angle_step) && done;
    done = approach(joints_.roll_rad, target_.roll_rad, angle_step) && done;
    done = approach(joints_.insertion_m, target_.insertion_m, linear_step) && done;
    done = approach(joints_.loop_travel_m, target_.loop_travel_m, linear_step) && done;
    if (done) state_ = ToolInputState::kTracking;
  }
}

}  // namespace resecto
