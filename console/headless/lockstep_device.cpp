// The emulator and the host decoder joined without a thread, for deterministic batch runs.
#include "console/headless/lockstep_device.h"

#include <cmath>
#include <cstdio>
#include <utility>

#include "device/link/calibration_adapter.h"
#include "resecto/lp3500_board.h"
#include "rtcore/base/units.h"

namespace resecto {

firmware::MotionScript motion_script_for(const Procedure& procedure) {
  // Copied in: the script outlives the caller's procedure.
  return [procedure](std::uint64_t time_us) {
    const ProcedureKeyframe k = procedure.sample(static_cast<double>(time_us) * 1e-6);
    firmware::MotionState m;
    m.yaw_rad = units::deg_to_rad(k.yaw_deg);
    m.pitch_rad = units::deg_to_rad(k.pitch_deg);
    m.roll_rad = units::deg_to_rad(k.roll_deg);
    m.insertion_mm = k.insertion_mm;
    m.loop_mm = k.loop_mm;
    m.cut = k.cut;
    m.coagulate = k.coagulate;
    return m;
  };
}

Status check_encoder_speeds(const Procedure& procedure) {
  const double counts_per_turn = firmware::SensorModel{}.counts_per_revolution;
  const double fastest_deg_s = LP3500_MAX_COUNT_RATE_HZ * 360.0 / counts_per_turn;
  const std::vector<ProcedureKeyframe>& k = procedure.keyframes;
  for (std::size_t i = 1; i < k.size(); ++i) {
    const double seconds = k[i].time_s - k[i - 1].time_s;
    const std::pair<const char*, double> turns[] = {{"yaw", k[i].yaw_deg - k[i - 1].yaw_deg},
                                                    {"pitch", k[i].pitch_deg - k[i - 1].pitch_deg},
                                                    {"roll", k[i].roll_deg - k[i - 1].roll_deg}};
    for (const auto& [joint, degrees] : turns) {
      if (std::abs(degrees) <= fastest_deg_s * seconds) continue;
      char text[400];
      std::snprintf(text, sizeof text,
                    "procedure '%s': from %.6g s to %.6g s the %s turns %.6g deg (%.0f deg/s); the resectoscope's encoders are "
                    "decoded up to %.0f deg/s (%u counts/s at %.0f counts a turn), past which the angle read is wrong for the rest "
                    "of the run: give that move at least %.3g s",
                    procedure.name.c_str(), k[i - 1].time_s, k[i].time_s, joint, degrees, std::abs(degrees) / seconds, fastest_deg_s,
                    LP3500_MAX_COUNT_RATE_HZ, counts_per_turn, std::abs(degrees) / fastest_deg_s);
      return Error{text};
    }
  }
  return Ok{};
}

LockstepDevice::LockstepDevice(const Procedure& procedure, const device::Calibration& calibration, std::uint64_t seed)
    : emulator_([&] {
        firmware::EmulatorOptions options;
        options.seed = seed;
        return options;
      }()),
      joints_(joint_calibration_from(calibration)) {
  emulator_.set_motion(motion_script_for(procedure));
}

void LockstepDevice::advance_to(std::uint64_t device_time_us, SpscRing<DeviceSample>& ring) {
  if (device_time_us > emulator_.time_us()) emulator_.advance(device_time_us - emulator_.time_us());
  // Reports come out in the order the board queued them: the order they would cross the wire.
  while (auto report = emulator_.read_input_report()) {
    ++counters_.reports;
    DecodedReport decoded = decode_input_report(*report, joints_);
    if (!decoded.valid) {
      ++counters_.rejected;
      continue;
    }
    std::uint64_t unwrapped = 0, gap = 0;
    const SequenceVerdict verdict = sequences_.observe(decoded.sequence32, unwrapped, gap);
    if (verdict == SequenceVerdict::kDuplicate || verdict == SequenceVerdict::kLate || verdict == SequenceVerdict::kStale) {
      ++counters_.duplicates;
      continue;
    }
    counters_.lost += gap;
    ++counters_.accepted;
    counters_.board_flags.count(decoded.sample.status);
    decoded.sample.sequence = unwrapped;
    decoded.sample.host_time_ns = static_cast<std::int64_t>(decoded.sample.device_time_us) * 1000;
    if (!ring.try_push(decoded.sample)) ++counters_.ring_full;
  }
}

}  // namespace resecto
