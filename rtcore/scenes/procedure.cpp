// The procedure text format, its interpolation, and the built-in demo.
#include "rtcore/scenes/procedure.h"

#include <algorithm>
#include <cmath>
#include <optional>

#include "rtcore/anatomy/resectoscope.h"
#include "rtcore/base/checked_number.h"
#include "rtcore/base/quoted_word.h"
#include "rtcore/base/text_file.h"

namespace resecto {
namespace {

// The demo: insert through the apex to mid-gland, survey by rolling the sheath, swing the loop into
// the left then the right lateral lobe and cut while drawing it back into the sheath's beak (the
// resection stroke: the pedal stays down until the loop has closed, which severs the chip), then
// withdraw. With the default registration the apex is at insertion 150 mm, the bladder neck at 191.5.
constexpr const char* kDemoProcedure = R"(# Resecto procedure v1: the built-in demo
# time_s  yaw_deg  pitch_deg  roll_deg  insertion_mm  loop_mm  cut  coagulate
0.0     0.0   0.0     0.0   125.0   0.0   0  0
1.5     0.0   0.0     0.0   158.0   0.0   0  0
2.5     0.0   0.0     0.0   172.0   0.0   0  0
3.0     0.0   0.0    25.0   172.0   0.0   0  0
3.5     0.0   0.0   -25.0   172.0   0.0   0  0
4.0     0.0   0.0    90.0   172.0   0.0   0  0
4.6     0.6   0.0    90.0   168.0  16.0   0  0
5.0     1.0   0.0    90.0   168.0  16.0   1  0
6.0     1.0   0.0    90.0   168.0   0.0   1  0
6.15    1.0   0.0    90.0   168.0   0.0   0  0
6.4     0.0   0.0    90.0   168.0   0.0   0  0
6.9     0.0   0.0   -90.0   168.0   0.0   0  0
7.3    -0.6   0.0   -90.0   168.0  16.0   0  0
7.6    -1.0   0.0   -90.0   168.0  16.0   1  0
8.6    -1.0   0.0   -90.0   168.0   0.0   1  0
8.75   -1.0   0.0   -90.0   168.0   0.0   0  0
9.2     0.0   0.0     0.0   160.0   0.0   0  0
10.0    0.0   0.0     0.0   125.0   0.0   0  0
)";

// The built-in full resection (`turp`), in the standard order: the median lobe at the bladder neck,
// then each lateral lobe, by strokes at successive roll angles and depths. A stroke: with the pedal up
// the sheath goes to where the stroke will end and the loop out to its bladder end; with the pedal
// down the loop is drawn back into the sheath's beak (the cut), which closes the stroke against the
// sheath and severs its chip; then the pedal comes up. Depth comes from tilting the sheath (yaw and
// pitch) toward the side the loop hangs to, a layer further at each pass. Every stroke ends proximal
// to the verumontanum (9.1 mm from the apex with the default gland) and starts short of the bladder
// neck, and the deepest layer stops short of the capsule.
struct TurpPlan {
  double apex_insertion_mm = 150.0;  // the sheath's tip at the apex, with the default registration
  double far_mm = 34.0;              // a lateral stroke's bladder end, from the apex: short of the neck's rim
  double near_mm = 11.0;             // where it closes: 1.9 mm proximal to the verumontanum
  double median_far_mm = 35.0;
  double median_near_mm = 26.0;      // the median lobe sits at the bladder neck
  double stroke_s = 1.2;             // the cut: loop drawn back at ~20 mm/s
  double close_s = 0.15;             // the pedal held down once the loop is in, so the filtered loop closes
  double move_s = 0.4;               // roll, tilt and loop out, pedal up: at least this long
  // A hand's pace between strokes, so that no move outruns the contact search's margin (1.5 mm over
  // two collision periods): rolls, tilts, the sheath's and the loop's travel at most this fast.
  double roll_deg_s = 60.0;
  double tilt_deg_s = 3.0;
  double loop_mm_s = 40.0;
  double insertion_mm_s = 20.0;
};

std::vector<ProcedureKeyframe> turp_keyframes() {
  const TurpPlan plan;
  // How far inside the tip the wire lies at zero travel: a stroke from `far_mm` travels this much more.
  const double retracted_mm = -1000.0 * ResectoscopeShape{}.retracted_loop_z_m;
  std::vector<ProcedureKeyframe> keys;
  double t = 0.0;
  auto add = [&](double dt, double yaw, double pitch, double roll, double insertion, double loop, bool cut) {
    t += dt;
    keys.push_back({t, yaw, pitch, roll, insertion, loop, cut, false});
  };
  keys.push_back({0.0, 0.0, 0.0, 0.0, 125.0, 0.0, false, false});
  add(1.5, 0.0, 0.0, 0.0, plan.apex_insertion_mm + plan.near_mm, 0.0, false);  // in through the apex
  // How long a move from the last keyframe to these joints takes at the plan's pace (at least `least_s`).
  auto paced = [&](double least_s, double yaw, double pitch, double roll, double insertion, double loop) {
    const ProcedureKeyframe& from = keys.back();
    return std::max({least_s, std::abs(roll - from.roll_deg) / plan.roll_deg_s, std::abs(yaw - from.yaw_deg) / plan.tilt_deg_s,
                     std::abs(pitch - from.pitch_deg) / plan.tilt_deg_s, std::abs(insertion - from.insertion_mm) / plan.insertion_mm_s,
                     std::abs(loop - from.loop_mm) / plan.loop_mm_s});
  };
  // Tilting by `tilt_deg` toward where the loop hangs at `roll_deg` (roll 0: posterior, +90: the
  // patient's left): yaw swings the tip toward +x, pitch lifts it toward +y.
  auto stroke = [&](double roll_deg, double tilt_deg, double far_mm, double near_mm) {
    const double roll = roll_deg * 3.141592653589793 / 180.0;
    const double yaw = tilt_deg * std::sin(roll), pitch = -tilt_deg * std::cos(roll);
    const double insertion = plan.apex_insertion_mm + near_mm, loop = far_mm - near_mm + retracted_mm;
    add(paced(plan.move_s * 0.5, yaw, pitch, roll_deg, insertion, 0.0), yaw, pitch, roll_deg, insertion, 0.0, false);
    add(paced(plan.move_s * 0.5, yaw, pitch, roll_deg, insertion, loop), yaw, pitch, roll_deg, insertion, loop, false);
    add(0.05, yaw, pitch, roll_deg, insertion, loop, true);
    add(plan.stroke_s, yaw, pitch, roll_deg, insertion, 0.0, true);
    add(plan.close_s, yaw, pitch, roll_deg, insertion, 0.0, false);
  };
  // Median lobe: posterior, at the bladder neck, three layers.
  for (double tilt : {0.0, 0.6, 1.2}) {
    for (double roll : {-25.0, 0.0, 25.0}) stroke(roll, tilt, plan.median_far_mm, plan.median_near_mm);
  }
  // Lateral lobes, left then right, layer by layer from the channel outward.
  for (double side : {1.0, -1.0}) {
    for (double tilt : {0.0, 1.0, 2.0, 3.0, 3.6}) {
      // The two deepest layers spare the anterolateral roll, where the capsule is nearest (closed at
      // the sheath's tip, the 3-degree layer there perforated the 1296-triangle gland).
      for (double roll : {20.0, 45.0, 70.0, 95.0, 115.0}) {
        if (tilt < 2.5 || roll < 100.0) stroke(side * roll, tilt, plan.far_mm, plan.near_mm);
      }
    }
  }
  const double last_insertion = keys.back().insertion_mm;
  add(paced(0.5, 0.0, 0.0, 0.0, last_insertion, 0.0), 0.0, 0.0, 0.0, last_insertion, 0.0, false);
  add(1.0, 0.0, 0.0, 0.0, 125.0, 0.0, false);  // out
  return keys;
}

/// "source:line:column: what", the column counting bytes from 1, as compilers write it.
Error position_error(const std::string& source, int line, std::size_t column, const std::string& what) {
  return Error{source + ":" + std::to_string(line) + ":" + std::to_string(column) + ": " + what};
}

}  // namespace

ProcedureKeyframe Procedure::sample(double time_s) const {
  if (keyframes.empty()) return {};
  if (time_s <= keyframes.front().time_s) return keyframes.front();
  if (time_s >= keyframes.back().time_s) return keyframes.back();
  // First keyframe strictly after time_s; keyframes are sorted by construction.
  const auto after = std::upper_bound(keyframes.begin(), keyframes.end(), time_s,
                                      [](double t, const ProcedureKeyframe& k) { return t < k.time_s; });
  const ProcedureKeyframe& b = *after;
  const ProcedureKeyframe& a = *(after - 1);
  const double u = (time_s - a.time_s) / (b.time_s - a.time_s);
  auto mix = [u](double x, double y) { return x + u * (y - x); };
  ProcedureKeyframe k = a;
  k.time_s = time_s;
  k.yaw_deg = mix(a.yaw_deg, b.yaw_deg);
  k.pitch_deg = mix(a.pitch_deg, b.pitch_deg);
  k.roll_deg = mix(a.roll_deg, b.roll_deg);
  k.insertion_mm = mix(a.insertion_mm, b.insertion_mm);
  k.loop_mm = mix(a.loop_mm, b.loop_mm);
  return k;
}

Result<Procedure> parse_procedure(const std::string& text, const std::string& source_name) {
  Procedure procedure;
  procedure.name = source_name;
  int number = 0;
  static const char* kColumns[] = {"time_s", "yaw_deg", "pitch_deg", "roll_deg", "insertion_mm", "loop_mm", "cut", "coagulate"};
  for (std::string_view line : text_lines(text)) {
    ++number;
    // A comment may also end a line ("2.0  0 0 0  80 0  1 0   # first stroke").
    if (const std::size_t comment = line.find('#'); comment != std::string_view::npos) line = line.substr(0, comment);
    const std::vector<TextWord> words = text_words(line, ",");
    if (words.empty()) continue;
    const auto error_at = [&](std::size_t word, const std::string& what) {
      return position_error(source_name, number, words[word].column, what);
    };
    if (words.size() > 8) return error_at(8, "more than 8 columns");
    if (words.size() < 8) {
      // A spreadsheet in a locale whose decimal mark is ',' exports ';' between columns (audit 32, F14).
      const std::string hint = line.find(';') != std::string_view::npos ? " (columns are separated by blanks or commas, not ';')" : "";
      return position_error(source_name, number, line.size() + 1,
                            "expected 8 columns (time_s yaw_deg pitch_deg roll_deg insertion_mm loop_mm cut coagulate), found " +
                                std::to_string(words.size()) + hint);
    }
    double v[8];
    for (std::size_t c = 0; c < 8; ++c) {
      // Decimal only, as the mesh readers take numbers: strtod also took hexadecimal ("0x3").
      const std::optional<double> parsed = parse_finite(words[c].text);
      if (!parsed) return error_at(c, std::string(kColumns[c]) + " is " + not_finite_kind(words[c].text) + ": " + quoted_word(words[c].text));
      v[c] = *parsed;
    }
    constexpr double kLimits[6][2] = {{0.0, 86400.0},           {-kMaxGimbalDeg, kMaxGimbalDeg}, {-kMaxGimbalDeg, kMaxGimbalDeg},
                                      {-kMaxRollDeg, kMaxRollDeg}, {0.0, kMaxInsertionMm},        {0.0, kMaxLoopMm}};
    for (std::size_t c = 0; c < 6; ++c) {
      if (auto problem = range_problem(kColumns[c], v[c], kLimits[c][0], kLimits[c][1])) return error_at(c, *problem);
    }
    for (std::size_t pedal = 6; pedal < 8; ++pedal) {
      if (v[pedal] != 0.0 && v[pedal] != 1.0) return error_at(pedal, std::string(kColumns[pedal]) + " must be 0 or 1");
    }
    if (!procedure.keyframes.empty() && !(v[0] > procedure.keyframes.back().time_s)) {
      return error_at(0, "time_s must increase from one keyframe to the next");
    }
    // Encoders count from where the device powers up, so every procedure starts at the home pose.
    if (procedure.keyframes.empty()) {
      for (std::size_t c = 1; c <= 3; ++c) {
        if (v[c] != 0.0) return error_at(c, "the first keyframe must have yaw, pitch and roll 0 (the device powers up at its home pose)");
      }
    }
    procedure.keyframes.push_back({v[0], v[1], v[2], v[3], v[4], v[5], v[6] != 0.0, v[7] != 0.0});
  }
  if (procedure.keyframes.empty()) return Error{source_name + ": no keyframes"};
  return procedure;
}

Result<Procedure> load_procedure(const std::filesystem::path& path) {
  Result<std::string> text = read_utf8_text_file(path, " the procedure file");
  if (!text) return Error{text.error()};
  return parse_procedure(*text, path.string());
}

namespace {

/// The built-in procedures' names, the list builtin_procedure() answers to.
bool is_builtin_name(std::string_view name) { return name == "demo" || name == "turp"; }

}  // namespace

Result<Procedure> builtin_procedure(const std::string& name) {
  if (name == "demo") return parse_procedure(kDemoProcedure, "demo");
  if (name == "turp") return Procedure{"turp", turp_keyframes()};
  // A name without '/' or '.' is taken for a built-in one; a file of that name is read as ./NAME.
  std::error_code error;
  std::string file_hint;
  if (std::filesystem::is_regular_file(name, error)) file_hint = "; to read the file " + name + ", write ./" + name;
  else if (std::filesystem::is_directory(name, error)) file_hint = "; " + name + " here is a folder, not a procedure file";
  return Error{"no built-in procedure '" + name + "' (built-in: demo, turp)" + file_hint};
}

bool names_a_builtin_procedure(const std::string& name_or_path) {
  return name_or_path.find('/') == std::string::npos && name_or_path.find('.') == std::string::npos;
}

Result<Procedure> find_procedure(const std::string& name_or_path) {
  return names_a_builtin_procedure(name_or_path) ? builtin_procedure(name_or_path) : load_procedure(name_or_path);
}

std::optional<std::string> shadowed_file_note(const std::string& name_or_path) {
  // A file named demo beside the user was passed over without a word (audit 32, F13).
  std::error_code error;
  if (!is_builtin_name(name_or_path) || !std::filesystem::exists(name_or_path, error)) return std::nullopt;
  return "note: --procedure " + name_or_path + " is the built-in procedure; to read the file " + name_or_path + " here, write ./" + name_or_path;
}

}  // namespace resecto
