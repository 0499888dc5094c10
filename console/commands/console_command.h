// The operator console's command-line options, shared by `resecto console` and `resecto run`
// without --headless, and the call that opens the console with them.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "rtcore/core/fixed_step_scheduler.h"
#include "rtcore/core/simulation.h"

namespace resecto::cli {

struct ConsoleCliOptions {
  std::string procedure = "demo";
  std::string device = "emulator";
  int triangles = 8640;
  std::string preset;
  std::string replay;
  std::string record;
  std::string actions;
  std::string screenshot;
  std::uint64_t frames = 0;
  std::string report;
  std::string trace;  ///< --trace: the core's stages and the console's frames, Chrome trace-event JSON
  int trace_events = 0;  ///< --trace-events: the stage timings the trace keeps (0: the headless run's default)
  std::vector<std::string> sets;
  bool lockstep = false;
  double start_insertion_mm = 165.0;
  int width = 0;   ///< 0: 1600, or the screen's work area if smaller
  int height = 0;  ///< 0: 1000, or the screen's work area if smaller
  double slow_frame_ms = 0.0;
  std::uint64_t slow_frame_every = 1;
  bool no_vsync = false;
  double view_scale = 0.0;
  int collision_hz = 60;
  int substeps = 16;
  std::int64_t spin_us = kDefaultRealtimeSpinUs;
  int physics_threads = default_physics_threads();
  std::uint64_t seed = 1;
  std::string calibration;
};

/// Adds the console's own options (device, preset, replay, actions, screenshot, window) to `command`;
/// `shared_with_run` leaves out those `resecto run` already has under the same names.
void add_console_options(CLI::App& command, ConsoleCliOptions& options, bool shared_with_run);

/// Opens the console and blocks until it closes; prints its summary. Throws std::runtime_error with
/// a one-line reason on a setup error (no display, a bad preset or actions file).
void open_console(const ConsoleCliOptions& options);

}  // namespace resecto::cli
