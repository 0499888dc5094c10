// Parsing the console's action scripts.
#include "console/gui/action_script.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <string_view>

#include "console/gui/replay_browser.h"
#include "console/live/core_session.h"
#include "device/input/manual_motion.h"
#include "rtcore/base/checked_number.h"
#include "rtcore/base/text_file.h"
#include "rtcore/base/units.h"
#include "rtcore/tissue/tissue_parameters.h"

namespace resecto::gui {
namespace {

/// A finite number as the command line reads one (parse_finite: "+40" too, as `--set stiffness=+40`).
bool parse_number(const std::string& text, double& out) {
  const std::optional<double> value = parse_finite(text);
  if (value) out = *value;
  return value.has_value();
}

/// The largest frame number a script may name (--frames' bound) and the largest drag, in pixels.
constexpr double kMaxFrame = 1e8;
constexpr double kMaxDragPixels = 1e5;

struct VerbSpec {
  const char* name;
  ActionVerb verb;
  std::size_t min_words, max_words;
};

constexpr VerbSpec kVerbs[] = {
    {"set", ActionVerb::kSet, 2, 2},       {"pedal", ActionVerb::kPedal, 2, 2},
    {"key", ActionVerb::kKey, 2, 2},       {"drag", ActionVerb::kDrag, 3, 3},
    {"pause", ActionVerb::kPause, 0, 0},   {"resume", ActionVerb::kResume, 0, 0},
    {"step", ActionVerb::kStep, 1, 1},     {"record", ActionVerb::kRecord, 1, 1},
    {"screenshot", ActionVerb::kScreenshot, 1, 1}, {"preset", ActionVerb::kPreset, 2, 2},
    {"replay", ActionVerb::kReplay, 1, 2}, {"quit", ActionVerb::kQuit, 0, 0},
};

const char* verb_name(ActionVerb verb) {
  for (const VerbSpec& v : kVerbs)
    if (v.verb == verb) return v.name;
  return "action";
}

}  // namespace

bool script_key_known(const std::string& name) {
  const bool letter_or_digit = name.size() == 1 && std::isalnum(static_cast<unsigned char>(name[0]));
  return letter_or_digit || name == "SPACE" || name == "space";
}

bool action_needs_manual_device(const Action& action) {
  switch (action.verb) {
    case ActionVerb::kPedal:
    case ActionVerb::kKey: return true;
    case ActionVerb::kDrag: return action.words[0] == "endoscope";
    case ActionVerb::kSet: return is_joint_key(action.words[0]);
    default: return false;
  }
}

bool is_joint_key(const std::string& key) {
  return key == "yaw" || key == "pitch" || key == "roll" || key == "insertion" || key == "loop";
}

Status check_set_action(const std::string& key, double value) {
  if (const std::optional<TissueParameter> id = find_tissue_parameter(key)) {
    TissueParameters check;
    return check.set(*id, value);
  }
  if (key == "speed") {
    // The core's own range: a slower value was clamped to it without a word (audit 8, G9).
    if (!(value >= kSlowestCoreSpeed && value <= 1.0)) return Error{"speed " + exact_number(value) + " is outside [1/64, 1] (of real time)"};
    return Ok{};
  }
  if (!is_joint_key(key)) return Error{"unknown key '" + key + "': a tissue parameter (resecto params), yaw, pitch, roll, insertion, loop or speed"};
  // The hand-driven device's travel, as its keys and sliders keep it (a value past it was clamped
  // without a word, audit 8, G9); the sheath turns freely, so any roll is one.
  const ManualMotionLimits travel;
  const auto within = [&](double low, double high, const char* unit) -> Status {
    if (value >= low && value <= high) return Ok{};
    return Error{key + " " + exact_number(value) + " is outside the device's travel [" + exact_number(low) + ", " + exact_number(high) + "] " + unit};
  };
  if (key == "yaw") return within(-units::rad_to_deg(travel.yaw_range_rad), units::rad_to_deg(travel.yaw_range_rad), "degrees");
  if (key == "pitch") return within(-units::rad_to_deg(travel.pitch_range_rad), units::rad_to_deg(travel.pitch_range_rad), "degrees");
  if (key == "insertion") return within(0.0, travel.insertion_max_mm, "mm");
  if (key == "loop") return within(0.0, travel.loop_max_mm, "mm");
  return Ok{};
}

Status check_replay_speed(double speed) {
  if (speed >= ReplayBrowser::kMinSpeed && speed <= ReplayBrowser::kMaxSpeed) return Ok{};
  return Error{"replay speed " + exact_number(speed) + " is outside [" + exact_number(ReplayBrowser::kMinSpeed) + ", " +
               exact_number(ReplayBrowser::kMaxSpeed) + "], the replay panel's range"};
}

Status check_actions_for_device(const std::vector<Action>& actions, bool manual_device, const std::string& source_name) {
  if (manual_device) return Ok{};
  for (const Action& a : actions) {
    if (!action_needs_manual_device(a)) continue;
    return Error{source_name + ":" + std::to_string(a.line) + ":" + std::to_string(a.column) + ": " + (a.verb == ActionVerb::kSet ? "set " + a.words[0] : std::string(verb_name(a.verb))) +
                 " drives the hand-driven device, and this session's joints and pedals follow the device; start with --device keyboard"};
  }
  return Ok{};
}

Result<std::vector<Action>> parse_actions(const std::string& text, const std::string& source_name) {
  std::vector<Action> actions;
  int number = 0;
  for (const std::string_view line : text_lines(text)) {
    ++number;
    // A comment starts at a word beginning with '#', so a path may hold one (shots/#2.png).
    std::vector<TextWord> all = text_words(line);
    const auto comment = std::find_if(all.begin(), all.end(), [](const TextWord& w) { return w.text.front() == '#'; });
    all.erase(comment, all.end());
    if (all.empty()) continue;
    std::vector<std::string> words;
    for (const TextWord& w : all) words.emplace_back(w.text);
    const std::string written(line.substr(all.front().column - 1, all.back().column - 1 + all.back().text.size() - (all.front().column - 1)));
    // "file:line:column: ", the column of the word at fault (from 1), as compilers write it.
    const auto at = [&](std::size_t word) {
      const std::size_t column = word < all.size() ? all[word].column : line.size() + 1;
      return source_name + ":" + std::to_string(number) + ":" + std::to_string(column) + ": ";
    };
    double frame = 0.0;
    // The bound is --frames' own: a larger number, past 2^64 above all, would not convert to a frame.
    // Digits only (a '+' may lead, as on the command line), as --frames and --keyframe take a count
    // ("1e1" was read as 10: audit 32, F14).
    const std::string_view count = words.size() < 2 ? std::string_view() : std::string_view(words[1]).substr(words[1].starts_with('+') ? 1 : 0);
    const bool digits = !count.empty() && std::all_of(count.begin(), count.end(), [](char c) { return c >= '0' && c <= '9'; });
    if (words.size() < 3 || words[0] != "frame" || !digits || !parse_number(words[1], frame) || frame > kMaxFrame) {
      return Error{at(words[0] != "frame" ? 0 : 1) + "expected 'frame N VERB ...' with N a whole number of frames up to 100000000, got '" + written + "'"};
    }
    const VerbSpec* spec = nullptr;
    for (const VerbSpec& v : kVerbs)
      if (words[2] == v.name) spec = &v;
    if (!spec) return Error{at(2) + "unknown action '" + words[2] + "' (set, pedal, key, drag, pause, resume, step, record, screenshot, preset, replay, quit)"};
    Action a;
    a.frame = static_cast<std::uint64_t>(frame);
    a.verb = spec->verb;
    a.line = number;
    a.column = all[all.size() > 3 ? 3 : 2].column;
    a.words.assign(words.begin() + 3, words.end());
    const std::string where = at(3);  // the first argument
    if (a.words.size() < spec->min_words || a.words.size() > spec->max_words) {
      // Appended piece by piece: `"-" + std::to_string(n)` trips GCC 12's -Wrestrict false positive at -O3.
      std::string message = at(2) + "'" + words[2] + "' takes " + std::to_string(spec->min_words);
      if (spec->max_words != spec->min_words) message.append("-").append(std::to_string(spec->max_words));
      message.append(" argument(s), got ").append(std::to_string(a.words.size()));
      return Error{message};
    }
    switch (a.verb) {
      case ActionVerb::kSet:
        if (!parse_number(a.words[1], a.value)) return Error{at(4) + "set " + a.words[0] + ": '" + a.words[1] + "' is not a number"};
        // Known keys and their ranges are checked here, before the window opens, not at frame N.
        if (Status valid = check_set_action(a.words[0], a.value); !valid) return Error{where + valid.error()};
        break;
      case ActionVerb::kPedal:
        if (a.words[0] != "cut" && a.words[0] != "coagulate") return Error{where + "pedal: expected cut or coagulate, got '" + a.words[0] + "'"};
        if (a.words[1] != "on" && a.words[1] != "off") return Error{at(4) + "pedal: expected on or off, got '" + a.words[1] + "'"};
        break;
      case ActionVerb::kKey:
        if (!script_key_known(a.words[0])) return Error{where + "key: '" + a.words[0] + "' is not a key (a letter, a digit or SPACE)"};
        if (a.words[1] != "down" && a.words[1] != "up") return Error{at(4) + "key: expected down or up, got '" + a.words[1] + "'"};
        break;
      case ActionVerb::kDrag:
        if (a.words[0] != "endoscope" && a.words[0] != "outside") return Error{where + "drag: expected endoscope or outside, got '" + a.words[0] + "'"};
        // Pixels, at most a few screens' worth: a larger drag overflowed the camera's floats and blanked the view.
        if (!parse_number(a.words[1], a.value) || !parse_number(a.words[2], a.value2) || std::abs(a.value) > kMaxDragPixels ||
            std::abs(a.value2) > kMaxDragPixels) {
          return Error{at(4) + "drag: DX and DY must be numbers of pixels within +-100000"};
        }
        break;
      case ActionVerb::kStep:
        if (!parse_number(a.words[0], a.value) || a.value < 1 || a.value != std::floor(a.value) || a.value > 1e7) {
          return Error{where + "step: expected a whole number of ticks in [1, 10000000], got '" + a.words[0] + "'"};
        }
        break;
      case ActionVerb::kPreset:
        if (a.words[0] != "save" && a.words[0] != "load") return Error{where + "preset: expected save or load, got '" + a.words[0] + "'"};
        break;
      case ActionVerb::kReplay: {
        const std::string& op = a.words[0];
        const bool takes_argument = op == "open" || op == "seek" || op == "speed";
        const bool plain = op == "play" || op == "pause" || op == "step" || op == "verify";
        if (!takes_argument && !plain) return Error{where + "replay: unknown operation '" + op + "' (open, play, pause, step, seek, speed, verify)"};
        if (takes_argument != (a.words.size() == 2)) return Error{where + "replay " + op + (takes_argument ? " needs one argument" : " takes no argument")};
        if ((op == "seek" || op == "speed") && !parse_number(a.words[1], a.value)) return Error{at(4) + "replay " + op + ": '" + a.words[1] + "' is not a number"};
        if (op == "speed") {
          if (Status valid = check_replay_speed(a.value); !valid) return Error{at(4) + valid.error()};
        }
        break;
      }
      default: break;
    }
    actions.push_back(std::move(a));
  }
  std::stable_sort(actions.begin(), actions.end(), [](const Action& a, const Action& b) { return a.frame < b.frame; });
  return actions;
}

Result<std::vector<Action>> load_actions(const std::filesystem::path& path) {
  Result<std::string> text = read_utf8_text_file(path, " the actions file");
  if (!text) return Error{text.error()};
  return parse_actions(*text, path.string());
}

}  // namespace resecto::gui
