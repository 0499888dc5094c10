// Validation and conversion of LP3500 input reports (layout: firmware/include/resecto/lp3500_protocol.h).
#include "device/link/report_decoder.h"

#include <numbers>

#include "resecto/lp3500_protocol.h"

namespace resecto {

const char* reject_reason_name(RejectReason reason) {
  switch (reason) {
    case RejectReason::kLength: return "length";
    case RejectReason::kReportId: return "report_id";
    case RejectReason::kVersion: return "version";
    case RejectReason::kCrc: return "crc";
    case RejectReason::kStaleSequence: return "stale_sequence";
  }
  return "unknown";
}

DecodedReport decode_input_report(std::span<const std::uint8_t> bytes, const JointCalibration& calibration) {
  DecodedReport decoded;
  // An empty span may carry a null pointer; reject it before handing the pointer to C.
  if (bytes.empty()) {
    decoded.reason = RejectReason::kLength;
    return decoded;
  }
  lp3500_input_report report;
  const lp3500_result result = lp3500_unpack_input_report(bytes.data(), bytes.size(), &report);
  switch (result) {
    case LP3500_OK: break;
    case LP3500_ERROR_REPORT_ID: decoded.reason = RejectReason::kReportId; return decoded;
    case LP3500_ERROR_VERSION: decoded.reason = RejectReason::kVersion; return decoded;
    case LP3500_ERROR_CRC: decoded.reason = RejectReason::kCrc; return decoded;
    default: decoded.reason = RejectReason::kLength; return decoded;
  }

  constexpr double kTwoPi = 2.0 * std::numbers::pi;
  const auto angle = [&](int axis) {
    const auto i = static_cast<std::size_t>(axis);
    return (static_cast<double>(report.encoder_counts[i]) - calibration.encoder_zero_counts[i]) /
           calibration.encoder_counts_per_rev[i] * kTwoPi;
  };
  decoded.valid = true;
  decoded.sequence32 = report.sequence;
  DeviceSample& sample = decoded.sample;
  sample.event = LinkEvent::kSample;
  sample.sequence = report.sequence;
  sample.device_time_us = report.device_time_us;
  sample.pedals = report.pedals;
  sample.status = report.status;
  sample.joints.yaw_rad = angle(0);
  sample.joints.pitch_rad = angle(1);
  sample.joints.roll_rad = angle(2);
  sample.joints.insertion_m = calibration.insertion_at_zero_reading_m + report.sheath_um * 1e-6;
  sample.joints.loop_travel_m = report.loop_um * 1e-6;
  return decoded;
}

}  // namespace resecto
