// The real-time device: transport, emulator (scripted or hand-driven) and the link thread.
#include "console/live/live_device.h"

#include <algorithm>
#include <cmath>

#include "console/headless/lockstep_device.h"
#include "device/link/calibration_adapter.h"
#include "device/transport/emulator_transport.h"

namespace resecto {
namespace {

// Slew limits of the hand-driven board. Turning: well under the encoders' 1758 deg/s decoding limit,
// well over what ManualMotionLimits asks for. Sliding (insertion, loop): a hand's pace, over the keys'
// 40 and 30 mm/s and no faster than the contact search follows (its 1.5 mm margin over two collision
// periods, 45 mm/s): a value typed into a joint field glides there as a hand would move, rather than
// jumping 15 mm in 40 ms and leaving a 90 N set-up spike as the debrief's peak force (audit 11).
constexpr double kFollowAngularRadPerS = 10.0;
constexpr double kFollowLinearMmPerS = 45.0;

double approach(double from, double to, double max_step) { return from + std::clamp(to - from, -max_step, max_step); }

}  // namespace

firmware::MotionScript ManualFollower::script() {
  target_script_ = handoff_.script();
  return [this](std::uint64_t time_us) {
    const firmware::MotionState target = target_script_(time_us);
    const double dt_s = static_cast<double>(time_us - std::min(time_us, last_time_us_)) * 1e-6;
    last_time_us_ = time_us;
    const double turn = kFollowAngularRadPerS * dt_s;
    const double slide = kFollowLinearMmPerS * dt_s;
    state_.yaw_rad = approach(state_.yaw_rad, target.yaw_rad, turn);
    state_.pitch_rad = approach(state_.pitch_rad, target.pitch_rad, turn);
    state_.roll_rad = approach(state_.roll_rad, target.roll_rad, turn);
    state_.insertion_mm = approach(state_.insertion_mm, target.insertion_mm, slide);
    state_.loop_mm = approach(state_.loop_mm, target.loop_mm, slide);
    state_.cut = target.cut;
    state_.coagulate = target.coagulate;
    return state_;
  };
}

LiveDevice::LiveDevice(const LiveDeviceOptions& options) {
  LinkConfig config;
  config.calibration = joint_calibration_from(options.calibration);
  if (options.source == DeviceSource::kHid) {
    transport_ = std::make_unique<HidTransport>(options.hid);
    description_ = "hid";
  } else {
    firmware::EmulatorOptions emulator_options;
    emulator_options.seed = options.seed;
    emulator_ = std::make_unique<firmware::Emulator>(emulator_options);
    // The script is set before the link thread first opens the board: it defines the power-up pose.
    if (options.source == DeviceSource::kEmulatorManual) {
      manual_ = std::make_unique<ManualFollower>(options.manual_start);
      emulator_->set_motion(manual_->script());
      description_ = "emulator (manual)";
    } else {
      emulator_->set_motion(motion_script_for(options.procedure));
      description_ = "emulator (procedure " + options.procedure.name + ")";
    }
    transport_ = std::make_unique<EmulatorTransport>(*emulator_, clock_);
  }
  link_ = std::make_unique<DeviceLink>(*transport_, clock_, config);
}

LiveDevice::~LiveDevice() { link_->stop(); }

void relay_link_samples(DeviceLink& link, SpscRing<DeviceSample>& core_ring, std::int64_t& newest_sample_host_ns) {
  DeviceSample sample;
  while (link.samples().try_pop(sample)) {
    if (sample.event == LinkEvent::kSample) newest_sample_host_ns = std::max(newest_sample_host_ns, sample.host_time_ns);
    core_ring.try_push(sample);
  }
}

}  // namespace resecto
