// Shared pieces of the device link tests: the scripted hand motion for the emulator, and a driver
// that polls a link on a virtual clock while draining its ring.
#pragma once

#include <cstdint>
#include <functional>
#include <vector>

#include "device/input/sweep_motion.h"
#include "device/link/device_link.h"
#include "firmware/emulator/lp3500_emulator.h"

namespace resecto::testing {

/// The tests' hand: the shared sweep (see device/input/sweep_motion.h for its timing).
inline firmware::MotionState smooth_motion(std::uint64_t time_us) { return sweep_motion(time_us); }

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
