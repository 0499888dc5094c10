// BoardFlagCounts: how many accepted reports carried each of the board's fault flags. A flag is the
// only sign the host gets that a reading is wrong: an encoder turned faster than its quadrature can
// be decoded (both channels changed between two captures) loses counts for good, so the decoded angle
// is off from then on while every report still passes its CRC (audit 9: a 25 degree yaw flick in
// 2 ms left the yaw at -28 degrees for the rest of a run that said nothing).
#pragma once

#include <array>
#include <cstdint>

namespace resecto {

struct BoardFlagCounts {
  std::array<std::uint64_t, 3> illegal_transitions{};  ///< reports flagging one, per encoder: yaw, pitch, roll
  std::uint64_t sheath_clamped = 0;  ///< sheath reading outside the calibrated range
  std::uint64_t loop_clamped = 0;    ///< Hall sum outside the table
  std::uint64_t stalls = 0;          ///< reports packed late (no data lost)
  std::uint64_t overruns = 0;        ///< a capture ring overflowed: readings were lost on the board
  std::uint64_t no_adc_sample = 0;   ///< no potentiometer or Hall sample fell in the report's period

  /// Counts one report's LP3500_STATUS_* bits.
  void count(std::uint16_t status);
};

}  // namespace resecto
