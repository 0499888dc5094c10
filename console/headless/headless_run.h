// The headless runner behind `resecto run --headless`: the emulated device drives the core through a
// procedure, in batch mode (deterministic, as fast as possible, the emulator in lockstep) or real
// time (the device link on its own thread, absolute tick deadlines), while a consumer thread takes the
// core's snapshots through the triple buffer. Ends with the report DESIGN.md's contract describes.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "device/calibration/calibration.h"
#include "rtcore/base/result.h"
#include "rtcore/base/state_hash.h"
#include "rtcore/core/fixed_step_scheduler.h"
#include "rtcore/core/simulation.h"
#include "rtcore/scenes/procedure.h"

namespace resecto {

/// The trace's default ring: 2^22 stage timings, 134 MB, the last ~13 minutes of a run at 960 Hz.
inline constexpr std::uint64_t kDefaultTraceEvents = 1u << 22;

struct HeadlessOptions {
  Procedure procedure;
  double seconds = 0.0;          ///< 0: the procedure's length
  bool realtime = false;
  SimulationConfig simulation;
  std::uint64_t seed = 1;        ///< the emulator's sensor noise
  std::string trace_path;        ///< empty: no trace
  std::uint64_t trace_events = kDefaultTraceEvents;  ///< the trace keeps the run's last this many stage timings
  std::string record_path;       ///< empty: no recording (recordings/: the session file replay reads)
  /// Writes the remaining tissue's surface here at the end, at rest positions, in millimetres
  /// (format by extension: .off, .obj, .ply, .stl); empty: none.
  std::string export_surface_path;
  double consumer_delay_ms = 0;  ///< makes the snapshot consumer slow on purpose (tests)
  std::int64_t spin_us = kDefaultRealtimeSpinUs;  ///< real time: spin this long before each tick instead of sleeping
  /// The device's calibration: sensor conversion and the registration that places the gimbal in the
  /// world (it replaces `simulation.gimbal`).
  device::Calibration calibration = device::default_calibration();
};

/// Everything a run produced.
struct HeadlessResult {
  std::uint64_t ticks = 0;
  std::uint64_t final_hash = 0;
  std::vector<std::uint64_t> collision_hashes;  ///< the state hash at every collision step
  nlohmann::ordered_json report;
  int interrupted_by = 0;  ///< the signal that ended the run early (console/live/interrupt.h), or 0
};

/// Runs the procedure; an error only for a setup failure (a bad model or an unwritable trace). A
/// SIGINT or SIGTERM noted by catch_interrupts() ends it at the next tick, with every output written
/// for the ticks run (the report says `"interrupted": "SIGINT"`).
Result<HeadlessResult> run_headless(const HeadlessOptions& options);

/// A few lines a person reads at the end of a run.
std::string summarize_report(const nlohmann::ordered_json& report);

/// The procedure's metrics as the reports write them (`metrics` in the headless and console reports).
nlohmann::ordered_json metrics_json(const ProcedureMetrics& metrics);

}  // namespace resecto
