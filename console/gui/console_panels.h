// The console's ImGui panels: simulation control (pause, steps, speed), tissue parameters, device,
// procedure metrics, profiler plots, recording and replay. Each reads the core's newest frame and
// changes things only through the ConsoleController.
#pragma once

#include <cstdint>
#include <string>

#include "console/gui/console_controller.h"

namespace resecto::gui {

void draw_simulation_panel(ConsoleController& console);
void draw_parameter_panel(ConsoleController& console);
void draw_device_panel(ConsoleController& console);
void draw_metrics_panel(ConsoleController& console);
void draw_profiler_panel(ConsoleController& console);
void draw_recording_panel(ConsoleController& console);
void draw_replay_panel(ConsoleController& console);

/// What a recording started at `start_tick` > 0 cannot do: a recording from mid-session holds no
/// state to re-simulate from. Said on the Recording panel and in the console's exit summary.
std::string mid_session_recording_note(std::uint64_t start_tick);

}  // namespace resecto::gui
