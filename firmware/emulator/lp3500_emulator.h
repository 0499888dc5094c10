// The LP3500 board without hardware: the firmware's own C code driven by the sensor front-end model,
// producing the exact bytes a real board sends (1 kHz input reports, feature reports). Deterministic
// for a given seed and motion script, so the core's batch mode can step it in lockstep.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <vector>

#include "firmware/emulator/sensor_model.h"
#include "resecto/lp3500_protocol.h"

struct lp3500_board;

namespace resecto::firmware {

/// What the hand does to the device at one instant (device frame, before calibration).
struct MotionState {
  double yaw_rad = 0.0;       ///< encoder 0
  double pitch_rad = 0.0;     ///< encoder 1
  double roll_rad = 0.0;      ///< encoder 2
  double insertion_mm = 0.0;  ///< sheath, 0-230 mm
  double loop_mm = 0.0;       ///< loop travel, 0-36 mm
  bool cut = false;
  bool coagulate = false;
};

/// A motion script: the device state at `time_us` since power-up. Called at the 40 kHz poll rate, in
/// increasing time, from the thread calling advance().
using MotionScript = std::function<MotionState(uint64_t time_us)>;

struct EmulatorOptions {
  uint64_t seed = 1;                     ///< noise seed
  uint32_t serial_number = 0x00E30001u;
  double potentiometer_noise_v = 0.002;  ///< RMS at the ADC input
  double hall_noise_v = 0.002;           ///< RMS per Hall channel at the ADC input
  SensorModel sensors;                   ///< the modelled hardware
};

/// The emulated board. Encoder edges are exact up to LP3500_MAX_COUNT_RATE_HZ (20 000 counts/s per
/// axis, 1758 deg/s at 4096 counts/rev); faster motion raises the illegal-transition flag.
class Emulator {
 public:
  explicit Emulator(const EmulatorOptions& options = {});
  ~Emulator();
  Emulator(const Emulator&) = delete;
  Emulator& operator=(const Emulator&) = delete;

  /// Replaces the motion script (the default holds everything at zero). Set before the first advance()
  /// it also defines the power-up state (counts start at zero there); later, a jump in the script is a
  /// jump of the hardware.
  void set_motion(MotionScript motion);

  /// Runs the board for `duration_us` of device time (rounded down to whole 25 us ticks; the
  /// remainder carries over): capture and ADC interrupts at their rates, the main loop after each
  /// tick unless stalled.
  void advance(uint64_t duration_us);

  /// Suspends the main loop for the next `duration_us` (the interrupts keep capturing).
  void stall_main_loop(uint64_t duration_us);

  /// Takes the oldest queued 64-byte input report, if any. The board queues 256 reports; a host that
  /// reads less often than that holds the main loop back and, past LP3500_MAX_STALL_MS, loses data
  /// (flagged OVERRUN), exactly as a real board whose USB endpoint is not polled.
  std::optional<std::array<uint8_t, LP3500_INPUT_REPORT_SIZE>> read_input_report();

  /// GET_FEATURE: the report's bytes, or empty for an unknown id.
  std::vector<uint8_t> get_feature_report(uint8_t report_id) const;

  /// SET_FEATURE: the board's answer (LP3500_OK or why it refused).
  lp3500_result set_feature_report(const uint8_t* data, size_t length);

  /// Device time since power-up, microseconds.
  uint64_t time_us() const;
  /// The true 4x count of encoder `axis` relative to power-up (what the board must report).
  int32_t true_encoder_count(unsigned axis) const;
  /// The motion script sampled at `time_us`.
  MotionState motion_at(uint64_t time_us) const { return motion_(time_us); }
  /// The board's RAM, for size reports and white-box tests.
  const lp3500_board& board() const { return *board_; }
  const EmulatorOptions& options() const { return options_; }

 private:
  void power_up();
  uint8_t port_at(uint64_t time_us, const MotionState& motion) const;

  EmulatorOptions options_;
  std::unique_ptr<lp3500_board> board_;
  MotionScript motion_;
  NoiseSource noise_;
  uint64_t ticks_ = 0;
  uint64_t remainder_us_ = 0;
  uint64_t stall_until_tick_ = 0;
  std::array<int32_t, LP3500_ENCODER_COUNT> initial_counts_{};
  std::array<int32_t, LP3500_ENCODER_COUNT> last_counts_{};
};

/// The reference device's Hall table from `model`: loop positions every 0.5 mm and the expected sums.
lp3500_calibration nominal_calibration(const SensorModel& model);

}  // namespace resecto::firmware
