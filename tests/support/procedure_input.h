// A scripted procedure as the core's per-tick input, without the emulated device in between: the
// keyframes' joints and pedals as they are written (the core-level tests' hand).
#pragma once

#include "rtcore/base/units.h"
#include "rtcore/core/simulation.h"
#include "rtcore/scenes/procedure.h"

namespace resecto {

inline TickInput procedure_input(const ProcedureKeyframe& k) {
  TickInput input;
  input.tool_present = true;
  input.joints.yaw_rad = units::deg_to_rad(k.yaw_deg);
  input.joints.pitch_rad = units::deg_to_rad(k.pitch_deg);
  input.joints.roll_rad = units::deg_to_rad(k.roll_deg);
  input.joints.insertion_m = units::mm_to_m(k.insertion_mm);
  input.joints.loop_travel_m = units::mm_to_m(k.loop_mm);
  input.cut = k.cut;
  input.coagulate = k.coagulate;
  return input;
}

inline TickInput procedure_input(const Procedure& procedure, std::uint64_t tick, double tick_s) {
  return procedure_input(procedure.sample(static_cast<double>(tick) * tick_s));
}

}  // namespace resecto
