// Turns one raw LP3500 input report into a DeviceSample: validation (length, report id, protocol
// version, CRC — the shared protocol header's checks) and conversion of encoder counts and the
// board's micrometre readings into joint values in SI units.
#pragma once

#include <array>
#include <cstdint>
#include <span>

#include "device/link/device_sample.h"

namespace resecto {

/// Why a report was turned away. Values 1..4 mirror lp3500_result's framing errors.
enum class RejectReason : std::uint8_t {
  kLength = 1,
  kReportId = 2,
  kVersion = 3,
  kCrc = 4,
  kStaleSequence = 5,  ///< valid, but older than the sequence window: neither late nor a restart
};
inline constexpr int kRejectReasonCount = 6;  ///< array size for counting by reason (index 0 unused)

/// A short constant name for messages and JSON keys.
const char* reject_reason_name(RejectReason reason);

/// The host-side conversion from board units to joints.
struct JointCalibration {
  std::array<double, 3> encoder_counts_per_rev{4096.0, 4096.0, 4096.0};  ///< yaw, pitch, roll (1024 lines, 4x)
  std::array<double, 3> encoder_zero_counts{0.0, 0.0, 0.0};  ///< counts at the joint's zero angle
  double insertion_at_zero_reading_m = 0.0;  ///< pivot-to-tip distance when the sheath reads 0 um
};

/// A decoded report, or the reason it was rejected.
struct DecodedReport {
  bool valid = false;
  RejectReason reason = RejectReason::kLength;
  std::uint32_t sequence32 = 0;  ///< the sequence as sent (before unwrapping)
  DeviceSample sample;           ///< filled when valid; sequence holds sequence32, host time unset
};

/// Validates and converts. Never reads outside `bytes`; any byte pattern is safe.
DecodedReport decode_input_report(std::span<const std::uint8_t> bytes, const JointCalibration& calibration);

}  // namespace resecto
