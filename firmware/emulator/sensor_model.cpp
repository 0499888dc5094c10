// Sensor physics for the emulator: closed-form field of a cylindrical magnet on its axis, linear
// Hall and potentiometer transfer functions, and the ADC's quantisation.
#include "firmware/emulator/sensor_model.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace resecto::firmware {

double SensorModel::potentiometer_v(double insertion_mm) const {
  const double slope = (potentiometer_v_at_travel - potentiometer_v_at_zero) / sheath_travel_mm;
  return potentiometer_v_at_zero + slope * insertion_mm;
}

double SensorModel::magnet_field_mt(double distance_mm) const {
  // Axial field of a uniformly magnetised cylinder at z from its face: Br/2 (z+L)/sqrt(R^2+(z+L)^2)
  // - Br/2 z/sqrt(R^2+z^2).
  const double r = magnet_radius_mm, z = distance_mm, zl = distance_mm + magnet_length_mm;
  return magnet_remanence_mt / 2.0 * (zl / std::sqrt(r * r + zl * zl) - z / std::sqrt(r * r + z * z));
}

std::array<double, 2> SensorModel::hall_v(double loop_mm) const {
  const double gap_a = hall_gap_mm + (loop_span_mm - loop_mm);
  const double gap_b = hall_gap_mm + loop_mm;
  const double a = hall_quiescent_v + hall_sensitivity_v_per_mt * magnet_field_mt(gap_a);
  const double b = hall_quiescent_v - hall_sensitivity_v_per_mt * magnet_field_mt(gap_b);
  return {std::clamp(a, 0.25, 4.75), std::clamp(b, 0.25, 4.75)};
}

uint16_t SensorModel::adc_code(double volts) const {
  const double code = std::round(volts / adc_reference_v * 4096.0);
  return static_cast<uint16_t>(std::clamp(code, 0.0, 4095.0));
}

uint16_t SensorModel::nominal_hall_sum(double loop_mm) const {
  const auto v = hall_v(loop_mm);
  return static_cast<uint16_t>(std::lround((v[0] + v[1]) / adc_reference_v * 4096.0));
}

int32_t SensorModel::encoder_count(double angle_rad) const {
  return static_cast<int32_t>(std::floor(angle_rad / (2.0 * std::numbers::pi) * counts_per_revolution));
}

uint64_t NoiseSource::next_u64() {
  uint64_t z = (state_ += 0x9E3779B97F4A7C15ull);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

double NoiseSource::uniform() { return static_cast<double>(next_u64() >> 11) * 0x1.0p-53; }

double NoiseSource::normal() {
  double sum = 0.0;
  for (int i = 0; i < 12; ++i) sum += uniform();  // fixed order: deterministic
  return sum - 6.0;
}

}  // namespace resecto::firmware
