// ToolInput: the core's side of the device link, called once per tick. It drains the SPSC ring,
// keeps the latest joints, and applies the safety rules: while disconnected the tool freezes where it
// was and the pedals read released; after reconnection the tool moves from the frozen pose to the
// device's new readings no faster than set speed limits (it never teleports), and cutting stays off
// until it has caught up. Deterministic: it depends only on the ring's contents and the tick length.
#pragma once

#include <cstdint>

#include "device/link/device_sample.h"
#include "rtcore/core/tick_input.h"
#include "rtcore/concurrency/spsc_ring.h"

namespace resecto {

/// Speed limits while re-engaging after a reconnection.
struct ReengageLimits {
  double max_angular_speed_rad_s = 1.5;  ///< yaw, pitch and roll
  double max_linear_speed_m_s = 0.05;    ///< insertion and loop travel
};

/// Where the tool's input stands this tick.
enum class ToolInputState : std::uint8_t {
  kNoDevice,      ///< nothing received yet: the tool has no pose from the device
  kTracking,      ///< following the device's readings
  kFrozen,        ///< disconnected: holding the last pose
  kReengaging,    ///< reconnected: slewing toward the new readings
};

class ToolInput {
 public:
  explicit ToolInput(ReengageLimits limits = {}) : limits_(limits) {}

  /// Drains `ring` and advances by one tick of `tick_s` seconds. Consumer thread only.
  void latch(SpscRing<DeviceSample>& ring, double tick_s);

  ToolInputState state() const { return state_; }
  /// The joints the tool should be placed by this tick.
  const DeviceJoints& joints() const { return joints_; }
  /// Pedal bits in force: zero unless tracking.
  std::uint8_t pedals() const { return state_ == ToolInputState::kTracking ? pedals_ : 0; }
  /// This tick's input in the core's terms: the joints, the pedals in force, whether a device has reported.
  TickInput tick_input() const {
    TickInput input;
    input.joints = joints_;
    input.cut = (pedals() & kPedalCut) != 0;
    input.coagulate = (pedals() & kPedalCoagulate) != 0;
    input.tool_present = state_ != ToolInputState::kNoDevice;
    return input;
  }
  /// The newest sample's sequence number and device time (0 before any).
  std::uint64_t last_sequence() const { return last_sequence_; }
  std::uint64_t last_device_time_us() const { return last_device_time_us_; }
  std::uint64_t samples_latched() const { return samples_latched_; }
  std::uint64_t disconnections_seen() const { return disconnections_seen_; }

 private:
  ReengageLimits limits_;
  ToolInputState state_ = ToolInputState::kNoDevice;
  DeviceJoints joints_;   ///< what the tool uses
  DeviceJoints target_;   ///< the device's newest reading
  bool have_target_ = false;
  std::uint8_t pedals_ = 0;
  std::uint64_t last_sequence_ = 0;
  std::uint64_t last_device_time_us_ = 0;
  std::uint64_t samples_latched_ = 0;
  std::uint64_t disconnections_seen_ = 0;
};

}  // namespace resecto
