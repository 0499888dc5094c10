// LockstepDevice: the emulated LP3500 stepped in lockstep with the core's ticks, for batch runs. The
// board runs to exactly the device time of each tick, and the reports it sent meanwhile are validated
// and converted by the host link's own decoder, so a headless run goes through the same bytes as a
// live one yet is deterministic: no thread, no host clock.
#pragma once

#include <array>
#include <cstdint>

#include "device/calibration/calibration.h"
#include "device/link/board_flags.h"
#include "device/link/report_decoder.h"
#include "device/link/sequence_tracker.h"
#include "firmware/emulator/lp3500_emulator.h"
#include "rtcore/base/result.h"
#include "rtcore/concurrency/spsc_ring.h"
#include "rtcore/scenes/procedure.h"

namespace resecto {

/// The board's motion script for a procedure (degrees and millimetres to the emulator's units).
firmware::MotionScript motion_script_for(const Procedure& procedure);

/// Refuses a procedure that turns yaw, pitch or roll faster than the emulated board's quadrature
/// decoding follows: past that the counts alias (a jump of three counts reads as one back), so the
/// angle the host reads is wrong from then on and no check downstream can tell.
Status check_encoder_speeds(const Procedure& procedure);

/// What the lockstep link saw.
struct LockstepCounters {
  std::uint64_t reports = 0;
  std::uint64_t accepted = 0;
  std::uint64_t lost = 0;
  std::uint64_t duplicates = 0;
  std::uint64_t rejected = 0;
  std::uint64_t ring_full = 0;  ///< samples the core's ring could not take
  BoardFlagCounts board_flags;  ///< the board's fault flags over the accepted reports
};

class LockstepDevice {
 public:
  LockstepDevice(const Procedure& procedure, const device::Calibration& calibration, std::uint64_t seed);

  /// Runs the board until `device_time_us` and moves every valid report it sent into `ring`.
  void advance_to(std::uint64_t device_time_us, SpscRing<DeviceSample>& ring);

  const LockstepCounters& counters() const { return counters_; }

 private:
  firmware::Emulator emulator_;
  JointCalibration joints_;
  SequenceTracker sequences_;
  LockstepCounters counters_;
};

}  // namespace resecto
