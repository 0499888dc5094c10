// The operator console (`resecto console`, and `resecto run` without --headless): a GLFW window with
// an OpenGL 3.3 core context and Dear ImGui, two-pane: the endoscopic and outside views on the left
// over the profiler, the panels on the right. The core runs on its own thread (CoreSession); the
// console draws from its newest frame and never blocks it.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "console/gui/console_state.h"
#include "console/live/core_session.h"
#include "rtcore/base/result.h"

namespace resecto::gui {

struct ConsoleOptions {
  CoreSessionOptions core;
  ConsoleSettings settings;
  std::string actions_path;     ///< --actions: the scripted input
  std::string screenshot_path;  ///< --screenshot: written after frame `frames`
  std::uint64_t frames = 0;     ///< --frames: quit after this many frames (0: run until closed)
  std::string report_path;      ///< --report: the session's JSON report
  std::string trace_path;       ///< --trace: the core's stages and the frames, Chrome trace-event JSON
  std::string record_path;      ///< --record: record the session from its first tick
  std::string replay_path;      ///< --replay: open this recording in the replay panel
  /// Every file the session reads (--actions, --preset, --replay, --calibration, a procedure file):
  /// no recording, screenshot, preset or report of the session may be written over one.
  std::vector<std::filesystem::path> input_paths;
  double slow_frame_ms = 0.0;   ///< every frame takes this much longer (tests of frame pacing)
  std::uint64_t slow_frame_every = 1;  ///< only every Nth frame is slowed (the others are the comparison)
  bool vsync = true;
  /// The views' resolution relative to their panels (drawn smaller and scaled up when below 1);
  /// 0: 1 on a GPU, 0.5 on a software rasteriser (llvmpipe), where every pixel costs CPU time.
  double view_scale = 0.0;
};

/// Runs the console; the report (also written to `report_path`) on a clean exit, an error when the
/// window, the OpenGL context, the model, a preset or the actions file cannot be set up.
Result<nlohmann::ordered_json> run_console(const ConsoleOptions& options);

/// The summary printed when the console closes.
std::string summarize_console_report(const nlohmann::ordered_json& report);

/// Whether a display server is reachable (DISPLAY or WAYLAND_DISPLAY set).
bool display_available();

}  // namespace resecto::gui
