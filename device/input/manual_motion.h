// Driving the emulated device by hand: keyboard keys or a gamepad's sticks and buttons become joint
// velocity commands, integrated (with the device's travel limits) into the emulator's motion state.
// The input is read on the console's thread and handed to the emulator's thread through an SPSC ring.
#pragma once

#include <functional>

#include "firmware/emulator/lp3500_emulator.h"
#include "rtcore/concurrency/spsc_ring.h"

struct GLFWgamepadstate;

namespace resecto {

/// What a person asks for this instant: each rate in [-1, 1] of its axis's top speed.
struct ManualCommand {
  double yaw = 0.0;        ///< + swings the tip toward +x
  double pitch = 0.0;      ///< + lifts the tip
  double roll = 0.0;
  double insertion = 0.0;  ///< + pushes the sheath in
  double loop = 0.0;       ///< + extends the loop
  bool cut = false;
  bool coagulate = false;
};

/// Top speeds and travel of the hand-driven device.
struct ManualMotionLimits {
  double yaw_rate_rad_s = 0.6;
  double pitch_rate_rad_s = 0.6;
  double roll_rate_rad_s = 2.0;
  double insertion_rate_mm_s = 40.0;
  double loop_rate_mm_s = 30.0;
  double yaw_range_rad = 0.6;    ///< |yaw| at most this (the disk-ring's swing)
  double pitch_range_rad = 0.5;
  double insertion_max_mm = 230.0;  ///< the potentiometer's travel
  double loop_max_mm = 36.0;
};

/// Integrates commands into a device state, clamped to the travel limits. Deterministic.
class ManualMotion {
 public:
  explicit ManualMotion(firmware::MotionState start = {}, ManualMotionLimits limits = {})
      : state_(start), limits_(limits) {}
  /// Applies `command` for `dt_s` seconds.
  void apply(const ManualCommand& command, double dt_s);
  const firmware::MotionState& state() const { return state_; }

 private:
  firmware::MotionState state_;
  ManualMotionLimits limits_;
};

/// Keyboard mapping: W/S insert/withdraw, A/D yaw, R/F pitch, Q/E roll, X/Z loop out/in, Space cut,
/// C coagulate. `key_down(glfw_key)` says whether a key is held.
ManualCommand command_from_keys(const std::function<bool(int glfw_key)>& key_down);

/// Gamepad mapping (GLFW's standard layout): left stick yaw/pitch, right stick roll/insertion,
/// triggers loop out/in, A cut, B coagulate; stick values inside `dead_zone` read as zero.
ManualCommand command_from_gamepad(const GLFWgamepadstate& pad, double dead_zone = 0.12);

/// Reads gamepad `joystick_id` through GLFW (glfwInit must have succeeded); false when none is there.
bool poll_gamepad(int joystick_id, ManualCommand& out, double dead_zone = 0.12);

/// Hands motion states from the input thread to the emulator's thread, newest wins.
class MotionHandoff {
 public:
  explicit MotionHandoff(firmware::MotionState start = {}) : latest_(start) {}
  /// Input thread: offers the newest state (dropped if the emulator has 64 unread ones).
  void publish(const firmware::MotionState& state) { (void)ring_.try_push(state); }
  /// The emulator's motion script: the newest state published so far (emulator thread only).
  firmware::MotionScript script();

 private:
  SpscRing<firmware::MotionState> ring_{64};
  firmware::MotionState latest_;
};

}  // namespace resecto
