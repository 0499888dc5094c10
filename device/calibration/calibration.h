// The device calibration as the host keeps it (the calibration file, JSON in millimetres): the
// board's sensor models (sheath gain/offset, the loop's Hall table), encoder resolutions, and the
// registration of the device frame to the world. Conversions to and from the board's integer form.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <string>

#include "resecto/lp3500_protocol.h"
#include "rtcore/base/result.h"

namespace resecto::device {

/// What the device can measure: the potentiometer and each Hall channel read 12-bit codes, and the loop
/// travels over the Hall table's 74 points, 0.5 mm apart.
inline constexpr double kAdcMaxCounts = 4095.0;
inline constexpr double kLoopTravelMm = (LP3500_HALL_TABLE_POINTS - 1) * LP3500_HALL_TABLE_STEP_UM * 1e-3;

/// One device's calibration. Defaults: the firmware's compiled-in calibration, 4096 counts/rev on
/// every axis, and the registration that puts the gimbal pivot (the device frame's origin) at world
/// (0, 0, -150) mm with the device axes along the world's, so zero yaw/pitch aims the sheath down the
/// procedural prostate's channel (world +z).
struct Calibration {
  double sheath_gain_mm_per_count = 0.0;   ///< sheath_mm = gain * potentiometer code + offset
  double sheath_offset_mm = 0.0;
  double sheath_min_mm = 0.0;              ///< calibrated range; the board clamps outside it
  double sheath_max_mm = 0.0;
  std::array<uint16_t, LP3500_HALL_TABLE_POINTS> hall_sum_counts{};  ///< Hall A + B codes per point
  std::array<double, LP3500_HALL_TABLE_POINTS> loop_mm{};            ///< loop travel per point
  std::array<int, LP3500_ENCODER_COUNT> encoder_counts_per_revolution{4096, 4096, 4096};  ///< yaw, pitch, roll
  std::array<std::array<double, 3>, 3> rotation{{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}};  ///< device -> world, row-major
  std::array<double, 3> translation_mm{0.0, 0.0, -150.0};  ///< device origin (gimbal pivot) in the world
};

/// The default calibration (see Calibration).
Calibration default_calibration();

/// The board's part of `calibration` in its integer units, validated as the board would.
Result<lp3500_calibration> to_board(const Calibration& calibration);

/// `base` with its sensor part replaced by the board's calibration.
Calibration from_board(const lp3500_calibration& board, const Calibration& base = default_calibration());

/// Parses calibration JSON; errors name `source` and the field at fault. Unknown and repeated keys are
/// refused, and so are sensor models that map the sensor's whole range outside the travel.
Result<Calibration> parse_calibration(const std::string& text, const std::string& source);

/// Reads and validates a calibration file.
Result<Calibration> read_calibration(const std::filesystem::path& path);

/// The calibration as JSON text (the file format; see firmware/README.md "Calibration file").
std::string calibration_to_json(const Calibration& calibration);

/// Writes atomically: a temporary file beside `path`, flushed, then renamed over it.
Status write_calibration(const Calibration& calibration, const std::filesystem::path& path);

}  // namespace resecto::device
