// The sensor front-end of the LP3500 interface as physics: encoder A/B lines from shaft angle, the
// sheath potentiometer's voltage, the loop's Hall pair from a magnet model, and a 12-bit ADC with
// noise. The emulator samples these; the tests use them as the truth the firmware must recover.
#pragma once

#include <array>
#include <cstdint>

namespace resecto::firmware {

/// Constants of the modelled hardware (defaults: the paper's device plus documented assumptions).
struct SensorModel {
  double adc_reference_v = 5.0;                  ///< 12-bit ADC full scale
  // Sheath potentiometer: linear divider, 4.50 V at 0 mm falling to 3.23 V at 230 mm (the paper).
  double potentiometer_v_at_zero = 4.50;
  double potentiometer_v_at_travel = 3.23;
  double sheath_travel_mm = 230.0;
  // Loop: a carriage with a cylindrical magnet at each end (radius 3 mm, length 6 mm, remanence
  // 1.2 T), each facing a linear ratiometric Hall sensor (2.5 V quiescent, 50 mV/mT, output clipped
  // to 0.25-4.75 V). Magnet A approaches sensor A as the loop extends, magnet B (reversed) leaves
  // sensor B, so the summed output rises monotonically, steep at the ends, flat in the middle.
  double magnet_radius_mm = 3.0;
  double magnet_length_mm = 6.0;
  double magnet_remanence_mt = 1200.0;
  double hall_sensitivity_v_per_mt = 0.050;
  double hall_quiescent_v = 2.5;
  double hall_gap_mm = 7.0;                      ///< magnet-to-sensor gap at the nearest position
  double loop_span_mm = 36.5;                    ///< table span: 74 points every 0.5 mm
  int counts_per_revolution = 4096;              ///< 1024-line encoders, 4x decoding

  /// Potentiometer wiper voltage at `insertion_mm` (not clamped: the sheath can be pulled past 0).
  double potentiometer_v(double insertion_mm) const;
  /// On-axis field of one magnet at `distance_mm` from its face, millitesla.
  double magnet_field_mt(double distance_mm) const;
  /// Hall A and Hall B output voltages with the loop at `loop_mm`.
  std::array<double, 2> hall_v(double loop_mm) const;
  /// Ideal (noise-free, mid-tread) ADC code of `volts`, clamped to 0..4095.
  uint16_t adc_code(double volts) const;
  /// The expected sum of the two Hall codes at `loop_mm` (what noise-dithered averages converge to).
  uint16_t nominal_hall_sum(double loop_mm) const;
  /// The 4x count of an encoder at `angle_rad` (floor of the exact count).
  int32_t encoder_count(double angle_rad) const;
};

/// A small deterministic generator (SplitMix64) with an approximately normal draw (Irwin-Hall of 12
/// uniforms: no libm, identical on every platform).
class NoiseSource {
 public:
  explicit NoiseSource(uint64_t seed) : state_(seed) {}
  uint64_t next_u64();
  /// Uniform in [0, 1).
  double uniform();
  /// Approximately N(0, 1), bounded to +-6.
  double normal();

 private:
  uint64_t state_;
};

}  // namespace resecto::firmware
