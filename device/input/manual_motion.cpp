// Keyboard and gamepad input mapped to the emulated device's motion.
#include "device/input/manual_motion.h"

#include <GLFW/glfw3.h>

#include <algorithm>
#include <cmath>

namespace resecto {
namespace {

double clamp_unit(double v) { return std::clamp(v, -1.0, 1.0); }

double dead_zoned(float raw, double dead_zone) {
  const double v = clamp_unit(static_cast<double>(raw));
  if (std::abs(v) <= dead_zone) return 0.0;
  // Rescale so the response starts at zero just outside the dead zone.
  return (v > 0 ? v - dead_zone : v + dead_zone) / (1.0 - dead_zone);
}

}  // namespace

void ManualMotion::apply(const ManualCommand& c, double dt_s) {
  const double dt = std::max(0.0, dt_s);
  state_.yaw_rad = std::clamp(state_.yaw_rad + clamp_unit(c.yaw) * limits_.yaw_rate_rad_s * dt,
                              -limits_.yaw_range_rad, limits_.yaw_range_rad);
  state_.pitch_rad = std::clamp(state_.pitch_rad + clamp_unit(c.pitch) * limits_.pitch_rate_rad_s * dt,
                                -limits_.pitch_range_rad, limits_.pitch_range_rad);
  state_.roll_rad += clamp_unit(c.roll) * limits_.roll_rate_rad_s * dt;  // the sheath turns freely
  state_.insertion_mm = std::clamp(state_.insertion_mm + clamp_unit(c.insertion) * limits_.insertion_rate_mm_s * dt,
                                   0.0, limits_.insertion_max_mm);
  state_.loop_mm = std::clamp(state_.loop_mm + clamp_unit(c.loop) * limits_.loop_rate_mm_s * dt, 0.0,
                              limits_.loop_max_mm);
  state_.cut = c.cut;
  state_.coagulate = c.coagulate;
}

ManualCommand command_from_keys(const std::function<bool(int glfw_key)>& key_down) {
  const auto axis = [&](int plus, int minus) { return (key_down(plus) ? 1.0 : 0.0) - (key_down(minus) ? 1.0 : 0.0); };
  ManualCommand c;
  c.insertion = axis(GLFW_KEY_W, GLFW_KEY_S);
  c.yaw = axis(GLFW_KEY_D, GLFW_KEY_A);
  c.pitch = axis(GLFW_KEY_R, GLFW_KEY_F);
  c.roll = axis(GLFW_KEY_E, GLFW_KEY_Q);
  c.loop = axis(GLFW_KEY_X, GLFW_KEY_Z);
  c.cut = key_down(GLFW_KEY_SPACE);
  c.coagulate = key_down(GLFW_KEY_C);
  return c;
}

ManualCommand command_from_gamepad(const GLFWgamepadstate& pad, double dead_zone) {
  ManualCommand c;
  c.yaw = dead_zoned(pad.axes[GLFW_GAMEPAD_AXIS_LEFT_X], dead_zone);
  c.pitch = -dead_zoned(pad.axes[GLFW_GAMEPAD_AXIS_LEFT_Y], dead_zone);  // GLFW's stick y is + down
  c.roll = dead_zoned(pad.axes[GLFW_GAMEPAD_AXIS_RIGHT_X], dead_zone);
  c.insertion = -dead_zoned(pad.axes[GLFW_GAMEPAD_AXIS_RIGHT_Y], dead_zone);
  // Triggers rest at -1 and travel to +1.
  const double out = (clamp_unit(pad.axes[GLFW_GAMEPAD_AXIS_RIGHT_TRIGGER]) + 1.0) * 0.5;
  const double in = (clamp_unit(pad.axes[GLFW_GAMEPAD_AXIS_LEFT_TRIGGER]) + 1.0) * 0.5;
  c.loop = out - in;
  c.cut = pad.buttons[GLFW_GAMEPAD_BUTTON_A] == GLFW_PRESS;
  c.coagulate = pad.buttons[GLFW_GAMEPAD_BUTTON_B] == GLFW_PRESS;
  return c;
}

bool poll_gamepad(int joystick_id, ManualCommand& out, double dead_zone) {
  GLFWgamepadstate pad;
  if (!glfwJoystickIsGamepad(joystick_id) || !glfwGetGamepadState(joystick_id, &pad)) return false;
  out = command_from_gamepad(pad, dead_zone);
  return true;
}

firmware::MotionScript MotionHandoff::script() {
  return [this](std::uint64_t) {
    (void)ring_.pop_latest(latest_);
    return latest_;
  };
}

}  // namespace resecto
