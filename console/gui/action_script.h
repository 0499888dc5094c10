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
  int line = 0;                    ///< where it was written, for messages
};

/// Parses a script; errors name the source, the line and what is wrong there. Actions come out
/// ordered by frame, and in written order within a frame.
Result<std::vector<Action>> parse_actions(const std::string& text, const std::string& source_name);
Result<std::vector<Action>> load_actions(const std::filesystem::path& path);

}  // namespace resecto::gui
