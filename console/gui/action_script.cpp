// Parsing the console's action scripts.
#include "console/gui/action_script.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <sstream>

#include "rtcore/base/text_file.h"

namespace resecto::gui {
namespace {

bool parse_number(const std::string& text, double& out) {
  const char* end = text.data() + text.size();
  const auto [ptr, error] = std::from_chars(text.data(), end, out);
  return error == std::errc{} && ptr == end && std::isfinite(out);
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

}  // namespace

Result<std::vector<Action>> parse_actions(const std::string& text, const std::string& source_name) {
  std::vector<Action> actions;
  std::istringstream lines(text);
  std::string line;
  int number = 0;
  while (std::getline(lines, line)) {
    ++number;
    if (const std::size_t hash = line.find('#'); hash != std::string::npos) line.resize(hash);
    std::istringstream fields(line);
    std::vector<std::string> words;
    for (std::string w; fields >> w;) words.push_back(w);
    if (words.empty()) continue;
    const std::string where = source_name + ":" + std::to_string(number) + ": ";
    double frame = 0.0;
    // The bound is --frames' own: a larger number, past 2^64 above all, would not convert to a frame.
    if (words.size() < 3 || words[0] != "frame" || !parse_number(words[1], frame) || frame < 0 || frame != std::floor(frame) || frame > kMaxFrame) {
      return Error{where + "expected 'frame N VERB ...' with N a whole number of frames up to 100000000, got '" + line + "'"};
    }
    const VerbSpec* spec = nullptr;
    for (const VerbSpec& v : kVerbs)
      if (words[2] == v.name) spec = &v;
    if (!spec) return Error{where + "unknown action '" + words[2] + "' (set, pedal, key, drag, pause, resume, step, record, screenshot, preset, replay, quit)"};
    Action a;
    a.frame = static_cast<std::uint64_t>(frame);
    a.verb = spec->verb;
    a.line = number;
    a.words.assign(words.begin() + 3, words.end());
    if (a.words.size() < spec->min_words || a.words.size() > spec->max_words) {
      // Appended piece by piece: `"-" + std::to_string(n)` trips GCC 12's -Wrestrict false positive at -O3.
      std::string message = where + "'" + words[2] + "' takes " + std::to_string(spec->min_words);
      if (spec->max_words != spec->min_words) message.append("-").append(std::to_string(spec->max_words));
      message.append(" argument(s), got ").append(std::to_string(a.words.size()));
      return Error{message};
    }
    switch (a.verb) {
      case ActionVerb::kSet:
        if (!parse_number(a.words[1], a.value)) return Error{where + "set " + a.words[0] + ": '" + a.words[1] + "' is not a number"};
        break;
      case ActionVerb::kPedal:
        if (a.words[0] != "cut" && a.words[0] != "coagulate") return Error{where + "pedal: expected cut or coagulate, got '" + a.words[0] + "'"};
        if (a.words[1] != "on" && a.words[1] != "off") return Error{where + "pedal: expected on or off, got '" + a.words[1] + "'"};
        break;
      case ActionVerb::kKey:
        if (a.words[1] != "down" && a.words[1] != "up") return Error{where + "key: expected down or up, got '" + a.words[1] + "'"};
        break;
      case ActionVerb::kDrag:
        if (a.words[0] != "endoscope" && a.words[0] != "outside") return Error{where + "drag: expected endoscope or outside, got '" + a.words[0] + "'"};
        // Pixels, at most a few screens' worth: a larger drag overflowed the camera's floats and blanked the view.
        if (!parse_number(a.words[1], a.value) || !parse_number(a.words[2], a.value2) || std::abs(a.value) > kMaxDragPixels ||
            std::abs(a.value2) > kMaxDragPixels) {
          return Error{where + "drag: DX and DY must be numbers of pixels within +-100000"};
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
        if ((op == "seek" || op == "speed") && !parse_number(a.words[1], a.value)) return Error{where + "replay " + op + ": '" + a.words[1] + "' is not a number"};
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
  Result<std::string> text = read_text_file(path, " the actions file");
  if (!text) return Error{text.error()};
  strip_utf8_bom(*text);
  return parse_actions(*text, path.string());
}

}  // namespace resecto::gui
