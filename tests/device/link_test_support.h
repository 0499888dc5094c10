// Shared pieces of the device link tests: a smooth hand motion for the emulator, the joints the link
// should report for it, and a driver that polls a link on a virtual clock while draining its ring.
#pragma once

#include <cmath>
#include <cstdint>
#include <functional>
#include <numbers>
#include <vector>

#include "device/link/device_link.h"
#include "firmware/emulator/lp3500_emulator.h"

namespace resecto::testing {

/// Every axis moving, well inside the encoders' count-rate limit; insertion through the prostate.
inline firmware::MotionState smooth_motion(std::uint64_t time_us) {
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

/// Polls `link` until `done()` or `max_polls`, moving every sample it delivers into `out`.
inline void poll_and_drain(DeviceLink& link, std::vector<DeviceSample>& out, const std::function<bool()>& done,
                           int max_polls = 10'000'000) {
  DeviceSample sample;
  for (int i = 0; i < max_polls && !done(); ++i) {
    link.poll_once();
    while (link.samples().try_pop(sample)) out.push_back(sample);
  }
}

}  // namespace resecto::testing
