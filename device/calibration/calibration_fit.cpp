// The two fits of the calibration procedure. Both keep the caliper rows' line numbers so that a
// refusal or a large residual points at the measurement to repeat.
#include "device/calibration/calibration_fit.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <optional>

#include "device/calibration/calibration.h"
#include "resecto/lp3500_sensors.h"
#include "rtcore/base/checked_number.h"

namespace resecto::device {
namespace {

std::string mm(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%.3f", v);
  return text;
}

template <class Fit>
void summarise(Fit& fit) {
  double sum_sq = 0.0;
  for (const Residual& r : fit.residuals) {
    sum_sq += r.residual_mm * r.residual_mm;
    fit.max_abs_mm = std::max(fit.max_abs_mm, std::abs(r.residual_mm));
  }
  fit.rms_mm = fit.residuals.empty() ? 0.0 : std::sqrt(sum_sq / static_cast<double>(fit.residuals.size()));
}

Result<std::vector<int>> require_columns(const NumericCsv& csv, const std::string& source,
                                         const std::vector<std::string>& names) {
  std::vector<int> indices;
  for (const auto& name : names) {
    const int index = csv.column(name);
    if (index < 0) return Error{source + ": missing column '" + name + "'"};
    indices.push_back(index);
  }
  return indices;
}

// The sheath travels 0-230 mm (the loop's travel and the ADC's codes are the calibration's, calibration.h).
constexpr double kSheathTravelMm = 230.0;

/// "<source>:<line>: <problem>" when `value` is outside [lo, hi] (NaN always is), else nothing.
std::optional<Error> row_problem(const std::string& source, int line, const char* what, double value, double lo, double hi) {
  if (auto problem = range_problem(what, value, lo, hi)) return Error{source + ":" + std::to_string(line) + ": " + *problem};
  return std::nullopt;
}

}  // namespace

Result<std::vector<SheathSample>> sheath_samples(const NumericCsv& csv, const std::string& source) {
  const auto columns = require_columns(csv, source, {"position_mm", "potentiometer_counts"});
  if (!columns) return Error{columns.error() + " (expected position_mm,potentiometer_counts)"};
  std::vector<SheathSample> samples;
  for (size_t r = 0; r < csv.rows.size(); ++r) {
    const double position = csv.rows[r][(*columns)[0]], counts = csv.rows[r][(*columns)[1]];
    if (auto e = row_problem(source, csv.lines[r], "position_mm", position, 0.0, kSheathTravelMm)) return *e;
    if (auto e = row_problem(source, csv.lines[r], "potentiometer_counts", counts, 0.0, kAdcMaxCounts)) return *e;
    samples.push_back({position, counts, csv.lines[r]});
  }
  return samples;
}

Result<std::vector<HallSample>> hall_samples(const NumericCsv& csv, const std::string& source) {
  const bool summed = csv.column("hall_sum_counts") >= 0;
  const auto columns = summed ? require_columns(csv, source, {"position_mm", "hall_sum_counts"})
                              : require_columns(csv, source, {"position_mm", "hall_a_counts", "hall_b_counts"});
  if (!columns) {
    return Error{columns.error() + " (expected position_mm,hall_sum_counts or position_mm,hall_a_counts,hall_b_counts)"};
  }
  std::vector<HallSample> samples;
  for (size_t r = 0; r < csv.rows.size(); ++r) {
    const auto& row = csv.rows[r];
    if (auto e = row_problem(source, csv.lines[r], "position_mm", row[(*columns)[0]], 0.0, kLoopTravelMm)) return *e;
    // Each count column within what the two 12-bit channels can sum to; the fit checks the sum.
    for (std::size_t c = 1; c < columns->size(); ++c) {
      const double limit = 2.0 * kAdcMaxCounts;
      if (auto e = row_problem(source, csv.lines[r], csv.columns[static_cast<std::size_t>((*columns)[c])].c_str(), row[(*columns)[c]], 0.0, limit)) return *e;
    }
    const double sum = summed ? row[(*columns)[1]] : row[(*columns)[1]] + row[(*columns)[2]];
    samples.push_back({row[(*columns)[0]], sum, csv.lines[r]});
  }
  return samples;
}

Result<SheathFit> fit_sheath(const std::vector<SheathSample>& samples, const std::string& source) {
  if (samples.size() < 2) return Error{source + ": need at least two sheath measurements"};
  // Centred sums (fixed order: the file's) keep the normal equations well conditioned.
  double mean_x = 0.0, mean_y = 0.0;
  for (const auto& s : samples) {
    mean_x += s.potentiometer_counts;
    mean_y += s.position_mm;
  }
  mean_x /= static_cast<double>(samples.size());
  mean_y /= static_cast<double>(samples.size());
  double sxx = 0.0, sxy = 0.0;
  for (const auto& s : samples) {
    sxx += (s.potentiometer_counts - mean_x) * (s.potentiometer_counts - mean_x);
    sxy += (s.potentiometer_counts - mean_x) * (s.position_mm - mean_y);
  }
  if (sxx <= 1e-12) return Error{source + ": every sheath measurement has the same potentiometer reading; cannot fit a slope"};
  // Checked before the gain: rows at one position fit a gain of 0, which the gain's message called
  // "outside +-0.5 mm/count" (audit 8, G12).
  const auto [lowest, highest] = std::minmax_element(samples.begin(), samples.end(),
                                                     [](const SheathSample& a, const SheathSample& b) { return a.position_mm < b.position_mm; });
  if (highest->position_mm <= lowest->position_mm) {
    return Error{source + ": every sheath measurement is at the same position (" + mm(lowest->position_mm) +
                 " mm): measure across the sheath's travel"};
  }
  SheathFit fit;
  fit.gain_mm_per_count = sxy / sxx;
  fit.offset_mm = mean_y - fit.gain_mm_per_count * mean_x;
  if (fit.gain_mm_per_count == 0.0) return Error{source + ": fitted gain 0 mm/count: the potentiometer readings do not follow the positions"};
  if (std::abs(fit.gain_mm_per_count) * 1e6 > LP3500_SHEATH_GAIN_LIMIT_NM) {
    return Error{source + ": fitted gain " + mm(fit.gain_mm_per_count) + " mm/count is outside the board's +-0.5 mm/count"};
  }
  fit.min_mm = samples.front().position_mm;
  fit.max_mm = samples.front().position_mm;
  for (const auto& s : samples) {
    fit.min_mm = std::min(fit.min_mm, s.position_mm);
    fit.max_mm = std::max(fit.max_mm, s.position_mm);
    const double fitted = fit.gain_mm_per_count * s.potentiometer_counts + fit.offset_mm;
    fit.residuals.push_back({s.line, s.position_mm, fitted - s.position_mm});
  }
  summarise(fit);
  // A gain fitted over a short stretch of the travel multiplies its errors out to the ends (two rows 1
  // mm apart gave a table of 10-11 mm); a caliper reads to a tenth of a millimetre and the
  // potentiometer is linear to well under one, so a row more than 2 mm off the line through the
  // others is a misread or mistyped measurement (one such row gave an rms residual of 64 mm).
  if (fit.max_mm - fit.min_mm < kMinSheathSpanMm) {
    return Error{source + ": the measurements cover only " + mm(fit.min_mm) + " to " + mm(fit.max_mm) + " mm; measure across at least " +
                 mm(kMinSheathSpanMm) + " mm of the sheath's travel"};
  }
  // Which row is wrong cannot be told from three (one bad row pulls the line toward itself and away
  // from the good ones): the message names where the line misses most and leaves the rows to the user.
  const auto worst = std::max_element(fit.residuals.begin(), fit.residuals.end(),
                                      [](const Residual& a, const Residual& b) { return std::abs(a.residual_mm) < std::abs(b.residual_mm); });
  if (std::abs(worst->residual_mm) > kMaxSheathResidualMm) {
    return Error{source + ":" + std::to_string(worst->line) + ": the line fitted through the rows misses this one (" + mm(worst->position_mm) +
                 " mm) by " + mm(std::abs(worst->residual_mm)) + " mm, more than " + mm(kMaxSheathResidualMm) +
                 ": a row is misread or mistyped; check them and measure again"};
  }
  return fit;
}

Result<HallFit> fit_hall_table(const std::vector<HallSample>& samples, const std::string& source) {
  // Sort by position (stable: equal positions keep file order), then average repeats.
  std::vector<HallSample> sorted = samples;
  std::stable_sort(sorted.begin(), sorted.end(),
                   [](const HallSample& a, const HallSample& b) { return a.position_mm < b.position_mm; });
  std::vector<HallSample> points;
  std::vector<int> repeats;
  for (const auto& s : sorted) {
    if (!points.empty() && std::abs(points.back().position_mm - s.position_mm) < 1e-9) {
      points.back().hall_sum_counts += s.hall_sum_counts;
      ++repeats.back();
    } else {
      points.push_back(s);
      repeats.push_back(1);
    }
  }
  for (size_t i = 0; i < points.size(); ++i) points[i].hall_sum_counts /= repeats[i];
  if (points.size() < 2) return Error{source + ": need Hall measurements at two or more positions"};

  const double direction = points[1].hall_sum_counts > points[0].hall_sum_counts ? 1.0 : -1.0;
  for (size_t i = 1; i < points.size(); ++i) {
    if (direction * (points[i].hall_sum_counts - points[i - 1].hall_sum_counts) <= 0.0) {
      return Error{source + ":" + std::to_string(points[i].line) + ": Hall sum " + mm(points[i].hall_sum_counts) +
                   " at " + mm(points[i].position_mm) + " mm does not continue the " +
                   (direction > 0 ? "rising" : "falling") + " trend (line " + std::to_string(points[i - 1].line) +
                   ": " + mm(points[i - 1].hall_sum_counts) + " at " + mm(points[i - 1].position_mm) +
                   " mm): no monotone table fits these measurements"};
    }
  }
  const double table_end_mm = (LP3500_HALL_TABLE_POINTS - 1) * LP3500_HALL_TABLE_STEP_UM * 1e-3;
  if (points.front().position_mm > kHallExtrapolationLimitMm ||
      points.back().position_mm < table_end_mm - kHallExtrapolationLimitMm) {
    return Error{source + ": measurements cover " + mm(points.front().position_mm) + " to " +
                 mm(points.back().position_mm) + " mm; the table needs 0 to " + mm(table_end_mm) +
                 " mm, extrapolated at most " + mm(kHallExtrapolationLimitMm) + " mm at either end"};
  }

  HallFit fit;
  size_t segment = 0;
  for (unsigned i = 0; i < LP3500_HALL_TABLE_POINTS; ++i) {
    const double x = i * LP3500_HALL_TABLE_STEP_UM * 1e-3;
    while (segment + 2 < points.size() && points[segment + 1].position_mm < x) ++segment;
    const HallSample& a = points[segment];
    const HallSample& b = points[segment + 1];
    const double value = a.hall_sum_counts + (b.hall_sum_counts - a.hall_sum_counts) * (x - a.position_mm) /
                                                 (b.position_mm - a.position_mm);
    const double rounded = std::round(value);
    if (rounded < 0.0 || rounded > 8190.0) {
      return Error{source + ": Hall sum at " + mm(x) + " mm extrapolates to " + mm(value) + ", outside 0-8190"};
    }
    fit.hall_sum_counts[i] = static_cast<uint16_t>(rounded);
    fit.loop_mm[i] = x;
    if (i > 0 && direction * (rounded - fit.hall_sum_counts[i - 1]) <= 0.0) {
      return Error{source + ": table points at " + mm(x - 0.5) + " and " + mm(x) + " mm both round to Hall sum " +
                   std::to_string(fit.hall_sum_counts[i]) + ": the sensor is too flat there for a monotone 0.5 mm table"};
    }
  }
  // Residuals through the board's own integer lookup, at quarter-count resolution.
  lp3500_calibration board = lp3500_default_calibration;
  for (unsigned i = 0; i < LP3500_HALL_TABLE_POINTS; ++i) {
    board.hall_sum[i] = fit.hall_sum_counts[i];
    board.loop_um[i] = static_cast<uint16_t>(i * LP3500_HALL_TABLE_STEP_UM);
  }
  for (const auto& s : samples) {
    uint8_t clamped = 0;
    const auto quarter_counts = static_cast<uint32_t>(std::lround(std::max(0.0, s.hall_sum_counts) * 4.0));
    const double fitted_mm = lp3500_loop_um(&board, quarter_counts, 4, &clamped) * 1e-3;
    fit.residuals.push_back({s.line, s.position_mm, fitted_mm - s.position_mm});
  }
  summarise(fit);
  // Repeats at one position 2000 counts apart made a table missing its own rows by 10 mm, written with
  // exit 0 (audit 8, G16); the sheath's fit refuses such rows too.
  const auto worst = std::max_element(fit.residuals.begin(), fit.residuals.end(),
                                      [](const Residual& a, const Residual& b) { return std::abs(a.residual_mm) < std::abs(b.residual_mm); });
  if (worst != fit.residuals.end() && std::abs(worst->residual_mm) > kMaxHallResidualMm) {
    return Error{source + ":" + std::to_string(worst->line) + ": the table through the rows (repeats averaged) misses this one (" +
                 mm(worst->position_mm) + " mm) by " + mm(std::abs(worst->residual_mm)) + " mm, more than " + mm(kMaxHallResidualMm) +
                 ": rows repeated at one position disagree; check them and measure again"};
  }
  return fit;
}

}  // namespace resecto::device
