// LiveDevice: the device as a real-time run sees it, the board (or its emulator) behind the host
// link's own thread. Shared by the headless real-time run and the operator console, so both go
// through the same transport, link and ring. The emulator is driven by a procedure's script or by
// hand (keyboard, mouse, gamepad, the console's sliders); the LP3500 itself is reached over hidapi.
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include "device/calibration/calibration.h"
#include "device/input/manual_motion.h"
#include "device/link/device_link.h"
#include "device/transport/hid_transport.h"
#include "device/transport/host_clock.h"
#include "rtcore/scenes/procedure.h"

namespace resecto {

/// Where the joints come from.
enum class DeviceSource : std::uint8_t {
  kEmulatorScript,  ///< the emulated board follows a procedure
  kEmulatorManual,  ///< the emulated board follows a person's keys, mouse, gamepad or sliders
  kHid,             ///< the LP3500 over USB HID
};

struct LiveDeviceOptions {
  DeviceSource source = DeviceSource::kEmulatorScript;
  Procedure procedure;                       ///< kEmulatorScript
  firmware::MotionState manual_start;        ///< kEmulatorManual: the pose the board powers up in
  HidSelector hid;                           ///< kHid
  device::Calibration calibration = device::default_calibration();
  std::uint64_t seed = 1;                    ///< the emulator's sensor noise
};

/// Keeps the hand-driven board physical: the emulator's script moves toward the newest pose a person
/// asked for no faster than the encoders can follow, so a slider dragged across its range (or a
/// slow frame that delivers a large step) never makes the quadrature jump. Runs on the link thread.
class ManualFollower {
 public:
  explicit ManualFollower(firmware::MotionState start) : handoff_(start), state_(start) {}
  /// Console thread: the pose asked for now.
  void publish(const firmware::MotionState& target) { handoff_.publish(target); }
  /// The emulator's motion script (link thread only).
  firmware::MotionScript script();

 private:
  MotionHandoff handoff_;
  firmware::MotionScript target_script_;
  firmware::MotionState state_;
  std::uint64_t last_time_us_ = 0;
};

class LiveDevice {
 public:
  explicit LiveDevice(const LiveDeviceOptions& options);
  ~LiveDevice();
  LiveDevice(const LiveDevice&) = delete;
  LiveDevice& operator=(const LiveDevice&) = delete;

  DeviceLink& link() { return *link_; }
  /// The hand-driven board's input, or null when the joints come from elsewhere.
  ManualFollower* manual() { return manual_.get(); }
  /// "emulator (procedure demo)", "emulator (manual)", "hid".
  const std::string& description() const { return description_; }

 private:
  SteadyHostClock clock_;
  std::unique_ptr<firmware::Emulator> emulator_;
  std::unique_ptr<ManualFollower> manual_;
  std::unique_ptr<DeviceTransport> transport_;
  std::unique_ptr<DeviceLink> link_;
  std::string description_;
};

/// Moves every sample the link has delivered into the core's ring, keeping the host receipt time of
/// the newest in `newest_sample_host_ns` (for latency figures). Core thread only.
void relay_link_samples(DeviceLink& link, SpscRing<DeviceSample>& core_ring, std::int64_t& newest_sample_host_ns);

}  // namespace resecto
