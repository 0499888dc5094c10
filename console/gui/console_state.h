// The console's state, in the three kinds STYLE.md keeps apart: saved settings (what a preset file
// holds and the command line sets), per-session UI state (cameras, the sliders' values, held keys,
// what the panels show) and the simulation's state, which the console only ever reads from the
// core's newest LiveFrame and changes only by sending CoreControls.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "console/gui/action_script.h"
#include "console/gui/replay_browser.h"
#include "console/gui/view_cameras.h"
#include "console/live/core_session.h"
#include "device/input/manual_motion.h"
#include "rtcore/base/timing_histogram.h"

namespace resecto::gui {

/// Saved settings: what outlives a session.
struct ConsoleSettings {
  TissueParameters parameters;  ///< the tissue the session starts with (a preset)
  int window_width = 0;   ///< 0: kDefaultWidth, or the primary screen's work area if narrower
  int window_height = 0;  ///< 0: kDefaultHeight, or the work area if lower
  static constexpr int kDefaultWidth = 1600, kDefaultHeight = 1000;
};

/// One parameter change followed from the widget (or action) to the frame that shows it.
struct ParameterChange {
  std::uint64_t id = 0;
  TissueParameter parameter = TissueParameter::kStiffness;
  double value = 0.0;
  std::uint64_t frame_sent = 0;
  std::int64_t stamped_tick = 0;      ///< the core's next tick when the console sent it
  std::int64_t applied_tick = -1;     ///< the tick the core applied it at (from its status)
  std::int64_t first_frame_shown = -1;  ///< the first frame drawn from a snapshot after that tick
  std::uint64_t shown_snapshot_tick = 0;
  double shown_value = 0.0;
};

/// The core's deadlines split by the kind of frame the console was drawing while they fell due:
/// slowed on purpose (--slow-frame-ms, every --slow-frame-every'th frame) or not. What a slow frame
/// does to the core is the difference between the two kinds' miss fractions in the same run, with
/// the machine's state shared by both.
class FramePacing {
 public:
  struct Kind {
    std::uint64_t frames = 0, ticks = 0, misses = 0;
    double wall_s = 0.0;
  };
  /// At the start of each frame, with the core's counts as its newest status gives them: they close
  /// the previous frame's interval, whose ticks and misses go to that frame's kind (the status lags
  /// the core by a snapshot at both ends of every interval alike).
  void frame_begins(std::uint64_t deadline_ticks, std::uint64_t deadline_misses, std::int64_t now_ns, bool this_frame_slow) {
    if (started_ && deadline_ticks >= ticks_ && deadline_misses >= misses_) {
      Kind& kind = previous_slow_ ? slow_ : normal_;
      ++kind.frames;
      kind.ticks += deadline_ticks - ticks_;
      kind.misses += deadline_misses - misses_;
      kind.wall_s += static_cast<double>(now_ns - begin_ns_) * 1e-9;
    }
    started_ = true;
    previous_slow_ = this_frame_slow;
    ticks_ = deadline_ticks;
    misses_ = deadline_misses;
    begin_ns_ = now_ns;
  }
  const Kind& slow() const { return slow_; }
  const Kind& normal() const { return normal_; }

 private:
  Kind slow_, normal_;
  bool started_ = false, previous_slow_ = false;
  std::uint64_t ticks_ = 0, misses_ = 0;
  std::int64_t begin_ns_ = 0;
};

/// Per-session UI state.
struct ConsoleUi {
  OrbitCamera orbit;
  EndoscopeLens lens;
  std::array<double, kTissueParameterCount> slider_values{};  ///< what the sliders show
  std::vector<ParameterChange> changes;
  std::uint64_t next_control_id = 1;
  // The hand-driven device: the pose asked for, and keys held by the action script.
  ManualMotion manual;
  std::array<bool, 512> script_keys{};
  bool script_cut = false, script_coagulate = false;
  bool gamepad_present = false;
  std::string gamepad_name;
  // Pause, steps and slow motion as last asked (the core's status says what holds).
  int speed_index = 0;
  int batch_steps = 960;
  // Presets.
  std::string preset_path = "tissue-preset.json";
  std::string preset_message;
  // Frames and their timing.
  std::uint64_t frame = 0;
  TimingHistogram frame_ms_as_us;       ///< frame time (stored in the histogram's microsecond unit as ms * 1000)
  TimingHistogram input_to_photon_us;   ///< device report received -> the frame that shows it, on screen
  std::array<float, 240> frame_history_ms{};
  std::uint32_t frame_history_next = 0;
  std::int64_t last_counted_sample_ns = 0;
  FramePacing pacing;  ///< the core's deadlines during slowed frames and during the others
  // Where the views were drawn last frame, window pixels (for screenshots and tests).
  std::array<float, 4> endoscope_rect{}, outside_rect{};
  std::vector<std::string> screenshots;
  std::string message;  ///< the last error a person should see (bad preset file, ...)
  // Recording and replay.
  std::string record_path = "session.rsrec";
  std::string record_message;  ///< why the Record button's path was refused, until it is pressed again
  std::string replay_path;
  std::string replay_message;
  ReplayBrowser replay;
  bool show_replay = false;  ///< the views show the replay instead of the live core
  std::int64_t recording_started_ns = 0;
  std::uint64_t recording_bytes_seen = 0;
};

}  // namespace resecto::gui
