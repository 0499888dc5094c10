// The emulator's loop: for every 25 us tick, sample the motion, drive the ADC interrupt (every tenth
// tick) and the capture interrupt with the resulting port and codes, then give the main loop a pass.
#include "firmware/emulator/lp3500_emulator.h"

#include <cmath>

#include "resecto/lp3500_board.h"
#include "resecto/lp3500_sensors.h"

namespace resecto::firmware {

namespace {

MotionState rest(uint64_t) { return {}; }

}  // namespace

Emulator::Emulator(const EmulatorOptions& options)
    : options_(options), board_(std::make_unique<lp3500_board>()), motion_(rest), noise_(options.seed) {
  power_up();
}

Emulator::~Emulator() = default;

void Emulator::power_up() {
  const MotionState start = motion_(0);
  const SensorModel& s = options_.sensors;
  initial_counts_ = {s.encoder_count(start.yaw_rad), s.encoder_count(start.pitch_rad), s.encoder_count(start.roll_rad)};
  last_counts_ = initial_counts_;
  // A calibration written before the script was set survives this re-power (it would be in flash).
  const lp3500_calibration calibration = board_->calibration;
  const uint8_t written = board_->calibration_written;
  lp3500_board_init(board_.get(), options_.serial_number, port_at(0, start));
  if (written) {
    board_->calibration = calibration;
    board_->calibration_written = written;
  }
}

void Emulator::set_motion(MotionScript motion) {
  motion_ = motion ? std::move(motion) : MotionScript(rest);
  if (ticks_ == 0) power_up();
}

uint64_t Emulator::time_us() const { return ticks_ * LP3500_TICK_US; }

uint8_t Emulator::port_at(uint64_t, const MotionState& m) const {
  const double angles[LP3500_ENCODER_COUNT] = {m.yaw_rad, m.pitch_rad, m.roll_rad};
  unsigned port = 0;
  for (unsigned e = 0; e < LP3500_ENCODER_COUNT; ++e) {
    port |= unsigned{lp3500_quadrature_state_of_count(options_.sensors.encoder_count(angles[e]))} << (2 * e);
  }
  if (m.cut) port |= LP3500_PEDAL_CUT << LP3500_PORT_PEDAL_SHIFT;
  if (m.coagulate) port |= LP3500_PEDAL_COAGULATE << LP3500_PORT_PEDAL_SHIFT;
  return static_cast<uint8_t>(port);
}

void Emulator::advance(uint64_t duration_us) {
  remainder_us_ += duration_us;
  const uint64_t ticks = remainder_us_ / LP3500_TICK_US;
  remainder_us_ -= ticks * LP3500_TICK_US;
  const SensorModel& s = options_.sensors;
  for (uint64_t i = 0; i < ticks; ++i) {
    const uint64_t t_us = ticks_ * LP3500_TICK_US;
    const MotionState m = motion_(t_us);
    // Noise is drawn only on ADC ticks and always three values, in a fixed order: the stream depends
    // on the seed and the tick count alone.
    if (ticks_ % LP3500_ADC_TICKS == 0) {
      const auto hall = s.hall_v(m.loop_mm);
      const double pot = s.potentiometer_v(m.insertion_mm) + options_.potentiometer_noise_v * noise_.normal();
      const double a = hall[0] + options_.hall_noise_v * noise_.normal();
      const double b = hall[1] + options_.hall_noise_v * noise_.normal();
      lp3500_adc_isr(board_.get(), s.adc_code(pot), s.adc_code(a), s.adc_code(b));
    }
    lp3500_capture_isr(board_.get(), port_at(t_us, m));
    last_counts_ = {s.encoder_count(m.yaw_rad), s.encoder_count(m.pitch_rad), s.encoder_count(m.roll_rad)};
    ++ticks_;
    if (ticks_ >= stall_until_tick_) lp3500_main_loop_step(board_.get());
  }
}

void Emulator::stall_main_loop(uint64_t duration_us) {
  stall_until_tick_ = ticks_ + (duration_us + LP3500_TICK_US - 1) / LP3500_TICK_US;
}

std::optional<std::array<uint8_t, LP3500_INPUT_REPORT_SIZE>> Emulator::read_input_report() {
  std::array<uint8_t, LP3500_INPUT_REPORT_SIZE> bytes{};
  if (!lp3500_take_input_report(board_.get(), bytes.data())) return std::nullopt;
  return bytes;
}

std::vector<uint8_t> Emulator::get_feature_report(uint8_t report_id) const {
  std::vector<uint8_t> bytes(LP3500_CALIBRATION_REPORT_SIZE);
  const unsigned size = lp3500_get_feature(board_.get(), report_id, bytes.data(), static_cast<unsigned>(bytes.size()));
  bytes.resize(size);
  return bytes;
}

lp3500_result Emulator::set_feature_report(const uint8_t* data, size_t length) {
  return lp3500_set_feature(board_.get(), data, static_cast<unsigned>(length));
}

int32_t Emulator::true_encoder_count(unsigned axis) const { return last_counts_[axis] - initial_counts_[axis]; }

lp3500_calibration nominal_calibration(const SensorModel& model) {
  lp3500_calibration c = lp3500_default_calibration;
  for (unsigned i = 0; i < LP3500_HALL_TABLE_POINTS; ++i) {
    const double loop_mm = 0.5 * i;
    c.loop_um[i] = static_cast<uint16_t>(i * LP3500_HALL_TABLE_STEP_UM);
    c.hall_sum[i] = model.nominal_hall_sum(loop_mm);
  }
  return c;
}

}  // namespace resecto::firmware
