// EmulatorTransport: the in-process LP3500 emulator (the firmware's own code behind a sensor model)
// as a transport. Device time is paced by the host clock — real time with the steady clock, instant
// with a virtual one — so the link sees the same bytes and timing it would see from the board.
#pragma once

#include <cstdint>

#include "device/transport/device_transport.h"
#include "device/transport/host_clock.h"
#include "firmware/emulator/lp3500_emulator.h"

namespace resecto {

/// Reports the host had not read when the device ran ahead (hidraw's per-reader queue holds 64).
inline constexpr std::uint64_t kEmulatedHostQueueReports = 64;

class EmulatorTransport final : public DeviceTransport {
 public:
  /// `emulator` keeps running (in device time) while the transport is closed, as a board would.
  EmulatorTransport(firmware::Emulator& emulator, HostClock& clock);

  Status open() override;
  void close() override { open_ = false; }
  bool is_open() const override { return open_; }
  Result<std::size_t> read_report(std::span<std::uint8_t> buffer, std::int64_t timeout_ns) override;
  Result<std::size_t> get_feature_report(std::uint8_t report_id, std::span<std::uint8_t> buffer) override;
  Status send_feature_report(std::span<const std::uint8_t> report) override;
  std::string describe() const override { return "emulator"; }

 private:
  /// Device time the board has reached when the host clock reads `host_ns`.
  std::uint64_t device_time_at(std::int64_t host_ns) const;
  /// Runs the board up to `device_time_us`, throwing away every report it queues meanwhile.
  void discard_until(std::uint64_t device_time_us);

  firmware::Emulator& emulator_;
  HostClock& clock_;
  std::int64_t origin_ns_ = 0;  ///< host time at device time 0
  bool started_ = false;
  bool open_ = false;
};

}  // namespace resecto
