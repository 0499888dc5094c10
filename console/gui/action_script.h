// The console's scripted input (`resecto console --actions FILE`): timed UI actions a person could do,
// played into the same paths the widgets use, so tests and tutorials drive the real window. One action
// per line, `frame N VERB ...`; `#` starts a comment. docs/commands.md's "Operator console" section lists
// every verb.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "rtcore/base/result.h"

namespace resecto::gui {

enum class ActionVerb : std::uint8_t {
  kSet,         ///< set KEY VALUE: a tissue parameter (its units), a joint (deg, mm) or speed
  kPedal,       ///< pedal cut|coagulate on|off
  kKey,         ///< key NAME down|up: hold or release a keyboard key (the manual device's keys)
  kDrag,        ///< drag endoscope|outside DX DY: a mouse drag across a view, pixels
  kPause,
  kResume,
  kStep,        ///< step N: run N ticks while paused
  kRecord,      ///< record FILE | record stop
  kScreenshot,  ///< screenshot FILE: the whole window as PNG
  kPreset,      ///< preset save|load FILE
  kReplay,      ///< replay open FILE | play | pause | step | seek SECONDS | speed X | verify
  kQuit,
};

struct Action {
  std::uint64_t frame = 0;
  ActionVerb verb = ActionVerb::kQuit;
  std::vector<std::string> words;  ///< the arguments after the verb, as written
  double value = 0.0;              ///< the numeric argument where the verb has one
  double value2 = 0.0;
  int line = 0;                    ///< where it was written, for messages: the line (from 1)
  std::size_t column = 1;          ///< and the column of its first argument, or of its verb if it has none
};

/// Parses a script; errors name the source, the line and what is wrong there. Actions come out
/// ordered by frame, and in written order within a frame.
Result<std::vector<Action>> parse_actions(const std::string& text, const std::string& source_name);
Result<std::vector<Action>> load_actions(const std::filesystem::path& path);

/// Whether a `key` action names a key the console can hold: a letter, a digit or SPACE.
bool script_key_known(const std::string& name);
/// Whether `key` (of `set KEY VALUE`) is a joint of the hand-driven device.
bool is_joint_key(const std::string& key);
/// `set KEY VALUE` checked without a session: KEY known, VALUE in its range (a joint's travel is
/// clamped by the device's limits, as the keys' is).
Status check_set_action(const std::string& key, double value);
/// `replay speed X`'s range, the replay panel's slider's.
Status check_replay_speed(double speed);
/// Whether the action drives the hand-driven device (pedals, keys, the endoscope drag, a joint).
bool action_needs_manual_device(const Action& action);
/// An error naming the first action that needs the hand-driven device when the session has none,
/// so the script is refused before the window opens rather than at that action's frame.
Status check_actions_for_device(const std::vector<Action>& actions, bool manual_device, const std::string& source_name);

}  // namespace resecto::gui
