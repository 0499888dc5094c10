// The emulator and the host decoder joined without a thread, for deterministic batch runs.
#include "console/headless/lockstep_device.h"

#include "device/link/calibration_adapter.h"
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
    decoded.sample.sequence = unwrapped;
    decoded.sample.host_time_ns = static_cast<std::int64_t>(decoded.sample.device_time_us) * 1000;
    if (!ring.try_push(decoded.sample)) ++counters_.ring_full;
  }
}

}  // namespace resecto
