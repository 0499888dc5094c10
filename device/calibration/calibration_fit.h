// Calibration from caliper measurements (the paper's laboratory procedure): the sheath's gain and
// offset by least squares, the loop's 74-point Hall table by interpolating measured Hall sums onto
// the 0.5 mm grid; residuals for the operator, refusal where no monotone table exists.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "device/calibration/calibration_csv.h"
#include "resecto/lp3500_protocol.h"
#include "rtcore/base/result.h"

namespace resecto::device {

/// One sheath measurement: caliper position and the potentiometer's mean ADC code there.
struct SheathSample {
  double position_mm = 0.0;
  double potentiometer_counts = 0.0;
  int line = 0;  ///< where it came from, for messages
};

/// One loop measurement: caliper position and the mean of hall_a + hall_b codes there.
struct HallSample {
  double position_mm = 0.0;
  double hall_sum_counts = 0.0;
  int line = 0;
};

/// A measurement's misfit: what the fitted model reads at it minus the caliper's position.
struct Residual {
  int line = 0;
  double position_mm = 0.0;
  double residual_mm = 0.0;
};

struct SheathFit {
  double gain_mm_per_count = 0.0;
  double offset_mm = 0.0;
  double min_mm = 0.0;  ///< the measured range becomes the calibrated range
  double max_mm = 0.0;
  std::vector<Residual> residuals;
  double rms_mm = 0.0;
  double max_abs_mm = 0.0;
};

struct HallFit {
  std::array<uint16_t, LP3500_HALL_TABLE_POINTS> hall_sum_counts{};
  std::array<double, LP3500_HALL_TABLE_POINTS> loop_mm{};
  std::vector<Residual> residuals;  ///< through the board's own integer lookup
  double rms_mm = 0.0;
  double max_abs_mm = 0.0;
};

/// Sheath CSV: columns `position_mm,potentiometer_counts`.
Result<std::vector<SheathSample>> sheath_samples(const NumericCsv& csv, const std::string& source);
/// Hall CSV: `position_mm,hall_sum_counts` or `position_mm,hall_a_counts,hall_b_counts`.
Result<std::vector<HallSample>> hall_samples(const NumericCsv& csv, const std::string& source);

/// The least stretch of the sheath's 230 mm travel the sheath measurements must cover, and the most
/// any of them may be off the fitted line.
inline constexpr double kMinSheathSpanMm = 50.0;
inline constexpr double kMaxSheathResidualMm = 2.0;

/// Least-squares line position = gain * counts + offset; needs two distinct readings, covering at
/// least kMinSheathSpanMm, none off the line by more than kMaxSheathResidualMm.
Result<SheathFit> fit_sheath(const std::vector<SheathSample>& samples, const std::string& source);

/// How far the table may be extrapolated past the measured range at either end.
inline constexpr double kHallExtrapolationLimitMm = 1.0;
/// The most a measured row may be off the table: only rows repeated at one position can be (the table
/// runs through their mean), and two that far apart are a misread, not the sensor's noise.
inline constexpr double kMaxHallResidualMm = 1.0;

/// The Hall table at 0, 0.5, ..., 36.5 mm. Refuses measurements whose Hall sums are not strictly
/// monotone in position, that cover too little of the travel, or whose table would round flat.
Result<HallFit> fit_hall_table(const std::vector<HallSample>& samples, const std::string& source);

}  // namespace resecto::device
