// ConsoleController: every change a person can make in the console, in one place, used alike by the
// widgets and by the action script (so a script drives exactly what a person drives). Changes to the
// simulation become CoreControls for the core's next tick; nothing here writes into the core.
#pragma once

#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "console/gui/console_state.h"

namespace resecto::gui {

/// What a file this session writes holds: one path holds one of them (audit 8, G1: a `record` action
/// onto --report's path lost the recording, a screenshot onto --record's path the screenshot).
enum class OutputKind { kRecording, kReport, kScreenshot, kPreset, kTrace };

class ConsoleController {
 public:
  ConsoleController(CoreSession& session, ConsoleUi& ui, ConsoleSettings& settings)
      : session_(session), ui_(ui), settings_(settings) {}

  /// The newest frame from the core (valid after the first refresh()).
  const LiveFrame& frame() const { return session_.frames().read_slot(); }
  /// Takes the core's newest frame; true when it is new.
  bool refresh();

  /// Queues a tissue parameter change stamped for the core's next tick; false with a message in
  /// ui.message when the value is out of range or the ring is full.
  bool set_parameter(TissueParameter id, double value);
  /// `set KEY VALUE` as the action script and the command line write it: a tissue parameter, a
  /// joint of the hand-driven device (yaw, pitch, roll in degrees; insertion, loop in millimetres) or
  /// the core's speed.
  Status set_by_key(const std::string& key, double value);
  void pause();
  void resume();
  void step(std::uint32_t ticks);
  void set_speed(double speed);
  /// The tissue the sliders ask for: every change sent, whether or not the core applied it yet.
  TissueParameters requested_parameters() const;
  /// Sends a change for each value of `wanted` that differs from requested_parameters() (a preset
  /// loaded, the Defaults button).
  void request_parameters(const TissueParameters& wanted);
  /// Saves requested_parameters(); a load goes through request_parameters().
  Status save_preset(const std::string& path);
  Status load_preset(const std::string& path);
  /// Moves the hand-driven device's yaw and pitch as a mouse drag across the endoscope image would.
  void drag_endoscope(float dx_pixels, float dy_pixels);
  bool manual_device() const;
  /// Starts recording the live session to `path` (the core creates the file at its next tick), once
  /// check_output() passes it.
  Status start_recording(const std::string& path);
  /// Whether `path` may be written as `kind`: check_output_path(), with the session's files it reads
  /// (the recording open for replay, and those of protect_inputs()) as inputs it would destroy, and
  /// never a path this session writes as another kind (nor a recording's, or its partial file's, twice).
  Status check_output(const std::string& path, OutputKind kind) const;
  /// Notes that this session writes `path` as `kind` (--report and --screenshot, before the first frame).
  void claim_output(const std::filesystem::path& path, OutputKind kind);
  /// Files the session reads (--actions, --preset, --replay): never written over by a recording,
  /// screenshot or preset this session makes.
  void protect_inputs(std::vector<std::filesystem::path> inputs) { inputs_ = std::move(inputs); }
  void stop_recording();
  /// Opens a recording in the replay panel and shows it in the views.
  Status open_replay(const std::string& path);
  /// `replay OP [ARG]` as the action script writes it: play, pause, step, seek S, speed X, verify.
  Status replay_operation(const std::string& op, double argument);

  /// Follows queued parameter changes to the frame that shows them (call once per new frame).
  void track_changes();

  CoreSession& session() { return session_; }
  ConsoleUi& ui() { return ui_; }
  ConsoleSettings& settings() { return settings_; }

 private:
  bool send(const CoreControl& control);

  CoreSession& session_;
  ConsoleUi& ui_;
  ConsoleSettings& settings_;
  std::vector<std::filesystem::path> inputs_;  // protect_inputs()
  std::vector<std::pair<std::filesystem::path, OutputKind>> claimed_;  // claim_output()
  bool recording_asked_ = false;  // start_recording() sent, stop_recording() not yet
  std::string recording_asked_path_;
};

}  // namespace resecto::gui
