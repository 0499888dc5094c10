// A scripted hand for the emulator: every axis sweeping slowly, the sheath moving through the
// prostate, the loop going out and back and cutting while it extends. Used by `device monitor
// --device emulator` and by the link tests, so both watch the same motion.
#pragma once

#include <cmath>
#include <cstdint>
#include <numbers>

#include "firmware/emulator/lp3500_emulator.h"

namespace resecto {

/// The device state `time_us` after power-up (well inside the encoders' count-rate limit). The
/// insertion is 170 +- 20 mm at 0.25 Hz: fastest (31 mm/s) at whole multiples of 2 s.
inline firmware::MotionState sweep_motion(std::uint64_t time_us) {
  const double t = static_cast<double>(time_us) * 1e-6;
  const double w = 2.0 * std::numbers::pi;
  firmware::MotionState m;
  m.yaw_rad = 0.2 * std::sin(w * 0.3 * t);
  m.pitch_rad = 0.1 * std::sin(w * 0.2 * t);
  m.roll_rad = 0.5 * std::sin(w * 0.1 * t);
  m.insertion_mm = 170.0 + 20.0 * std::sin(w * 0.25 * t);
  m.loop_mm = 18.0 - 12.0 * std::cos(w * 0.5 * t);
  m.cut = std::sin(w * 0.5 * t) > 0.0;
  return m;
}

}  // namespace resecto
