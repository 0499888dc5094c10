// DeviceTransport: where raw LP3500 HID reports come from — the hidapi device, the in-process
// emulator, a recorded stream, or a fault-injecting wrapper around any of them. The link thread sees
// only this interface, so every layer above it runs the same with or without hardware.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>

#include "rtcore/base/result.h"

namespace resecto {

/// Large enough for any LP3500 report (full-speed HID interrupt reports are at most 64 bytes).
inline constexpr std::size_t kMaxRawReportBytes = 64;

/// A source of raw input reports and a sink/source of feature reports. Used by one thread at a time.
class DeviceTransport {
 public:
  virtual ~DeviceTransport() = default;

  /// Connects (or reconnects). An error names the device and why it could not be opened.
  virtual Status open() = 0;
  /// Disconnects; safe to call when closed.
  virtual void close() = 0;
  virtual bool is_open() const = 0;

  /// Reads one input report (first byte: report id) into `buffer`, waiting at most `timeout_ns`.
  /// Returns its length, 0 when nothing came within the timeout, or an error when the device is gone.
  virtual Result<std::size_t> read_report(std::span<std::uint8_t> buffer, std::int64_t timeout_ns) = 0;

  /// Reads feature report `report_id` into `buffer` (first byte: report id); returns its length.
  virtual Result<std::size_t> get_feature_report(std::uint8_t report_id, std::span<std::uint8_t> buffer) = 0;
  /// Sends a feature report (first byte: report id).
  virtual Status send_feature_report(std::span<const std::uint8_t> report) = 0;

  /// One line naming the transport and device, for messages and the monitor's header.
  virtual std::string describe() const = 0;
};

}  // namespace resecto
