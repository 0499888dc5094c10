// The procedure text format, its interpolation, and the built-in demo.
#include "rtcore/scenes/procedure.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <optional>
#include <sstream>

#include "rtcore/base/checked_number.h"
#include "rtcore/base/text_file.h"

namespace resecto {
namespace {

// The demo: insert through the apex to mid-gland, survey by rolling the sheath, swing the loop into
// the left then the right lateral lobe and cut while retracting it (the resection stroke), then
// withdraw. With the default registration the apex is at insertion 150 mm, the bladder neck at 191.5.
constexpr const char* kDemoProcedure = R"(# Resecto procedure v1: the built-in demo
# time_s  yaw_deg  pitch_deg  roll_deg  insertion_mm  loop_mm  cut  coagulate
0.0     0.0   0.0     0.0   125.0   0.0   0  0
1.5     0.0   0.0     0.0   158.0   0.0   0  0
2.5     0.0   0.0     0.0   172.0   0.0   0  0
3.0     0.0   0.0    25.0   172.0   0.0   0  0
3.5     0.0   0.0   -25.0   172.0   0.0   0  0
4.0     0.0   0.0    90.0   172.0   0.0   0  0
4.6     0.6   0.0    90.0   168.0  12.0   0  0
5.0     1.0   0.0    90.0   168.0  12.0   1  0
6.0     1.0   0.0    90.0   168.0   1.0   1  0
6.3     0.0   0.0    90.0   168.0   1.0   0  0
6.8     0.0   0.0   -90.0   168.0   1.0   0  0
7.3    -0.6   0.0   -90.0   168.0  12.0   0  0
7.6    -1.0   0.0   -90.0   168.0  12.0   1  0
8.6    -1.0   0.0   -90.0   168.0   1.0   1  0
8.9     0.0   0.0   -90.0   168.0   0.0   0  0
9.4     0.0   0.0     0.0   160.0   0.0   0  0
10.0    0.0   0.0     0.0   125.0   0.0   0  0
)";

Error line_error(const std::string& source, int line, const std::string& what) {
  return Error{source + ":" + std::to_string(line) + ": " + what};
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
  std::istringstream lines(text);
  std::string line;
  int number = 0;
  static const char* kColumns[] = {"time_s", "yaw_deg", "pitch_deg", "roll_deg", "insertion_mm", "loop_mm", "cut", "coagulate"};
  while (std::getline(lines, line)) {
    ++number;
    const auto first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos || line[first] == '#') continue;
    std::istringstream words(line);
    double v[8];
    int count = 0;
    std::string word;
    while (words >> word) {
      if (count == 8) return line_error(source_name, number, "more than 8 columns");
      char* end = nullptr;
      v[count] = std::strtod(word.c_str(), &end);
      if (end == word.c_str() || *end != '\0' || !std::isfinite(v[count])) {
        return line_error(source_name, number, std::string(kColumns[count]) + " is not a number: '" + word + "'");
      }
      ++count;
    }
    if (count != 8) {
      return line_error(source_name, number, "expected 8 columns (time_s yaw_deg pitch_deg roll_deg insertion_mm loop_mm cut coagulate), found " +
                                                 std::to_string(count));
    }
    auto out_of = [&](int column, double lo, double hi) -> std::optional<Error> {
      if (auto problem = range_problem(kColumns[column], v[column], lo, hi)) return line_error(source_name, number, *problem);
      return std::nullopt;
    };
    for (auto check : {out_of(0, 0.0, 86400.0), out_of(1, -kMaxGimbalDeg, kMaxGimbalDeg), out_of(2, -kMaxGimbalDeg, kMaxGimbalDeg),
                       out_of(3, -kMaxRollDeg, kMaxRollDeg), out_of(4, 0.0, kMaxInsertionMm), out_of(5, 0.0, kMaxLoopMm)}) {
      if (check) return *check;
    }
    for (int pedal = 6; pedal < 8; ++pedal) {
      if (v[pedal] != 0.0 && v[pedal] != 1.0) return line_error(source_name, number, std::string(kColumns[pedal]) + " must be 0 or 1");
    }
    if (!procedure.keyframes.empty() && !(v[0] > procedure.keyframes.back().time_s)) {
      return line_error(source_name, number, "time_s must increase from one keyframe to the next");
    }
    // Encoders count from where the device powers up, so every procedure starts at the home pose.
    if (procedure.keyframes.empty() && (v[1] != 0.0 || v[2] != 0.0 || v[3] != 0.0)) {
      return line_error(source_name, number, "the first keyframe must have yaw, pitch and roll 0 (the device powers up at its home pose)");
    }
    procedure.keyframes.push_back({v[0], v[1], v[2], v[3], v[4], v[5], v[6] != 0.0, v[7] != 0.0});
  }
  if (procedure.keyframes.empty()) return Error{source_name + ": no keyframes"};
  return procedure;
}

Result<Procedure> load_procedure(const std::filesystem::path& path) {
  Result<std::string> text = read_text_file(path, " the procedure file");
  if (!text) return Error{text.error()};
  return parse_procedure(*text, path.string());
}

Result<Procedure> builtin_procedure(const std::string& name) {
  if (name == "demo") return parse_procedure(kDemoProcedure, "demo");
  return Error{"no built-in procedure '" + name + "' (built-in: demo)"};
}

Result<Procedure> find_procedure(const std::string& name_or_path) {
  if (name_or_path.find('/') == std::string::npos && name_or_path.find('.') == std::string::npos) {
    return builtin_procedure(name_or_path);
  }
  return load_procedure(name_or_path);
}

}  // namespace resecto
