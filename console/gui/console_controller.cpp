// The console's changes, turned into commands for the core.
#include "console/gui/console_controller.h"

#include <cmath>

#include "console/gui/action_script.h"
#include "console/gui/tissue_presets.h"
#include "recordings/recording_writer.h"
#include "rtcore/base/atomic_file.h"
#include "rtcore/base/checked_number.h"
#include "rtcore/base/units.h"

namespace resecto::gui {

bool ConsoleController::refresh() { return session_.frames().update(); }

bool ConsoleController::send(const CoreControl& control) {
  if (session_.send(control)) return true;
  ui_.message = "the core's command ring is full; try again";
  return false;
}

bool ConsoleController::set_parameter(TissueParameter id, double value) {
  TissueParameters check;
  if (Status valid = check.set(id, value); !valid) {
    ui_.message = valid.error();
    return false;
  }
  CoreControl control;
  control.kind = CoreControlKind::kParameter;
  control.id = ui_.next_control_id++;
  // "The next tick": the one the core has not run yet. If the core gets there before it reads the
  // ring, it applies the change at its next tick and says which.
  control.parameter = {static_cast<std::int64_t>(session_.next_tick()), id, value};
  if (!send(control)) return false;
  ui_.slider_values[static_cast<std::size_t>(id)] = value;
  ParameterChange change;
  change.id = control.id;
  change.parameter = id;
  change.value = value;
  change.frame_sent = ui_.frame;
  change.stamped_tick = control.parameter.apply_tick;
  ui_.changes.push_back(change);
  return true;
}

bool ConsoleController::manual_device() const {
  return session_.live_device() && session_.live_device()->manual();
}

Status ConsoleController::set_by_key(const std::string& key, double value) {
  if (const std::optional<TissueParameter> id = find_tissue_parameter(key)) {
    if (!set_parameter(*id, value)) return Error{ui_.message};
    return Ok{};
  }
  if (key == "speed") {
    if (Status valid = check_set_action(key, value); !valid) return valid;
    set_speed(value);
    return Ok{};
  }
  const bool joint = key == "yaw" || key == "pitch" || key == "roll" || key == "insertion" || key == "loop";
  if (!joint) return Error{"unknown key '" + key + "': a tissue parameter (resecto params), yaw, pitch, roll, insertion, loop or speed"};
  if (!manual_device()) return Error{"set " + key + ": the joints follow the device; start with --device keyboard to set them"};
  firmware::MotionState state = ui_.manual.state();
  if (key == "yaw") state.yaw_rad = units::deg_to_rad(value);
  if (key == "pitch") state.pitch_rad = units::deg_to_rad(value);
  if (key == "roll") state.roll_rad = units::deg_to_rad(value);
  if (key == "insertion") state.insertion_mm = value;
  if (key == "loop") state.loop_mm = value;
  // Through ManualMotion so the device's travel limits hold for a slider as for the keys.
  ui_.manual = ManualMotion(state);
  ui_.manual.apply(ManualCommand{}, 0.0);
  return Ok{};
}

namespace {

const char* output_kind_name(OutputKind kind) {
  switch (kind) {
    case OutputKind::kRecording: return "recording";
    case OutputKind::kReport: return "report";
    case OutputKind::kScreenshot: return "screenshot";
    case OutputKind::kPreset: return "preset";
    case OutputKind::kTrace: return "trace";
  }
  return "output";
}

}  // namespace

Status ConsoleController::check_output(const std::string& path, OutputKind kind) const {
  std::vector<std::filesystem::path> inputs = inputs_;
  if (!ui_.replay_path.empty()) inputs.emplace_back(ui_.replay_path);
  if (Status writable = check_output_path(path, inputs); !writable) return writable;
  for (const auto& [claimed, claimed_kind] : claimed_) {
    // A screenshot or preset may be taken again over its own file; a recording is never replaced by
    // this session's next one.
    if ((claimed_kind != kind || kind == OutputKind::kRecording) && names_one_file(claimed, path)) {
      return Error{path + ": is this session's " + output_kind_name(claimed_kind) + " (" + claimed.string() + "); writing the " +
                   output_kind_name(kind) + " there would lose it (give another path)"};
    }
  }
  if (kind == OutputKind::kRecording) return rec::check_partial_recording_path(path, inputs);
  return Ok{};
}

void ConsoleController::claim_output(const std::filesystem::path& path, OutputKind kind) {
  if (path.empty()) return;
  claimed_.emplace_back(path, kind);
  if (kind == OutputKind::kRecording) {
    if (Result<std::filesystem::path> partial = rec::partial_recording_path(path)) claimed_.emplace_back(*partial, kind);
  }
}

Status ConsoleController::start_recording(const std::string& path) {
  // One recording at a time; a second start used to be dropped without a word (audit 8, G5). Asked
  // and not yet taken by the core counts as running, unless the core said it could not start it.
  if (recording_asked_ && (frame().status.recording || frame().status.recording_message[0] == '\0')) {
    return Error{"record " + path + ": a recording is running already (" + recording_asked_path_ + "); `record stop` it first"};
  }
  if (Status writable = check_output(path, OutputKind::kRecording); !writable) return writable;
  CoreControl control;
  control.kind = CoreControlKind::kRecordStart;
  control.path = path;
  if (!send(control)) return Error{ui_.message};
  claim_output(path, OutputKind::kRecording);
  recording_asked_ = true;
  recording_asked_path_ = path;
  ui_.recording_started_ns = FrameProfiler::now_ns();
  return Ok{};
}

void ConsoleController::stop_recording() {
  if (send({CoreControlKind::kRecordStop, {}, 0, 0, 1.0, {}})) recording_asked_ = false;
}

Status ConsoleController::open_replay(const std::string& path) {
  if (Status opened = ui_.replay.open(path); !opened) {
    ui_.replay_message = opened.error();
    return opened;
  }
  ui_.replay_path = path;
  ui_.show_replay = true;
  ui_.replay_message = "opened " + path;
  return Ok{};
}

Status ConsoleController::replay_operation(const std::string& op, double argument) {
  ReplayBrowser& r = ui_.replay;
  if (!r.is_open()) return Error{"replay " + op + ": no recording is open (replay open FILE first)"};
  ui_.show_replay = true;
  if (op == "play") r.play();
  else if (op == "pause") r.pause();
  else if (op == "step") r.step();
  else if (op == "seek") r.seek(argument);
  else if (op == "speed") {
    if (Status valid = check_replay_speed(argument); !valid) return valid;
    r.set_speed(argument);
  } else if (op == "verify") r.start_verification();
  else return Error{"replay: unknown operation '" + op + "'"};
  return Ok{};
}

void ConsoleController::pause() { send({CoreControlKind::kPause, {}, 0, 0, 1.0, {}}); }
void ConsoleController::resume() { send({CoreControlKind::kResume, {}, 0, 0, 1.0, {}}); }
void ConsoleController::step(std::uint32_t ticks) { send({CoreControlKind::kStep, {}, 0, ticks, 1.0, {}}); }
void ConsoleController::set_speed(double speed) { send({CoreControlKind::kSpeed, {}, 0, 0, speed, {}}); }

TissueParameters ConsoleController::requested_parameters() const {
  TissueParameters requested;
  requested.values = ui_.slider_values;
  return requested;
}

void ConsoleController::request_parameters(const TissueParameters& wanted) {
  // Every value that differs from what the sliders ask for (a change not yet in force included)
  // becomes a command, in table order.
  const TissueParameters requested = requested_parameters();
  for (const TissueParameterSpec& spec : tissue_parameter_specs()) {
    if (wanted.get(spec.id) != requested.get(spec.id)) set_parameter(spec.id, wanted.get(spec.id));
  }
}

Status ConsoleController::save_preset(const std::string& path) {
  Status saved = check_output(path, OutputKind::kPreset);
  // What the sliders were set to, changes not yet in force included: the frame a change first shows
  // may run its actions before it reads that snapshot, and an instructor saves what they chose.
  if (saved) saved = gui::save_preset(path, requested_parameters());
  if (saved) claim_output(path, OutputKind::kPreset);
  ui_.preset_message = saved ? "saved " + path : saved.error();
  return saved;
}

Status ConsoleController::load_preset(const std::string& path) {
  Result<TissueParameters> loaded = gui::load_preset(path, requested_parameters());
  if (!loaded) {
    ui_.preset_message = loaded.error();
    return Error{loaded.error()};
  }
  request_parameters(*loaded);
  settings_.parameters = *loaded;
  ui_.preset_message = "loaded " + path;
  return Ok{};
}

void ConsoleController::drag_endoscope(float dx_pixels, float dy_pixels) {
  if (!manual_device()) return;
  firmware::MotionState state = ui_.manual.state();
  // A drag to the right swings the tip right in the image; up lifts it (0.1 degree per pixel).
  state.yaw_rad += units::deg_to_rad(0.1 * dx_pixels);
  state.pitch_rad -= units::deg_to_rad(0.1 * dy_pixels);
  ui_.manual = ManualMotion(state);
  ui_.manual.apply(ManualCommand{}, 0.0);  // clamps to the travel limits
}

void ConsoleController::track_changes() {
  const LiveFrame& f = frame();
  for (ParameterChange& change : ui_.changes) {
    if (change.first_frame_shown >= 0) continue;
    const auto p = static_cast<std::size_t>(change.parameter);
    if (f.status.applied_id[p] < change.id) continue;
    change.applied_tick = f.status.applied_tick[p];
    change.first_frame_shown = static_cast<std::int64_t>(ui_.frame);
    change.shown_snapshot_tick = f.snapshot.tick;
    change.shown_value = f.status.parameters.get(change.parameter);
  }
}

}  // namespace resecto::gui
