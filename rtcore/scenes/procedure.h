// Procedures: scripted motions of the resectoscope (time-stamped 5-DOF and pedal keyframes, linearly
// interpolated) that drive the emulator in headless runs, tests and benchmarks. Built-ins `demo` and `turp`;
// users write their own in the text format documented in docs/commands.md.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "rtcore/base/result.h"

namespace resecto {

/// The device's five joints and two pedals at one instant, in the units a person writes them.
struct ProcedureKeyframe {
  double time_s = 0.0;
  double yaw_deg = 0.0;
  double pitch_deg = 0.0;
  double roll_deg = 0.0;
  double insertion_mm = 0.0;  ///< pivot to sheath tip, 0..230 (the apex is at 150 with the default registration)
  double loop_mm = 0.0;       ///< loop travel out of the tip, 0..36
  bool cut = false;
  bool coagulate = false;
};

/// A named motion: keyframes in strictly increasing time.
struct Procedure {
  std::string name;
  std::vector<ProcedureKeyframe> keyframes;

  double duration_s() const { return keyframes.empty() ? 0.0 : keyframes.back().time_s; }
  /// Joints interpolated linearly between the keyframes around `time_s` (held before the first and
  /// after the last); pedals hold the value of the last keyframe at or before `time_s`.
  ProcedureKeyframe sample(double time_s) const;
};

/// Joint limits a procedure must respect (the device's mechanical ranges).
inline constexpr double kMaxGimbalDeg = 30.0;
inline constexpr double kMaxRollDeg = 720.0;
inline constexpr double kMaxInsertionMm = 230.0;
inline constexpr double kMaxLoopMm = 36.0;

/// Parses the text format; errors name the line and the column at fault.
Result<Procedure> parse_procedure(const std::string& text, const std::string& source_name);
Result<Procedure> load_procedure(const std::filesystem::path& path);
/// The built-in procedure called `name` ("demo" or "turp"), or an error listing the built-in names.
Result<Procedure> builtin_procedure(const std::string& name);
/// Whether find_procedure() takes `name_or_path` as a built-in name (no '/' and no '.') or a file path.
bool names_a_builtin_procedure(const std::string& name_or_path);
/// A built-in name or a file path.
Result<Procedure> find_procedure(const std::string& name_or_path);
/// When `name_or_path` is a built-in procedure's name and a file of that name is also in the current
/// folder, the note that says which was taken and how to read the file; otherwise nothing.
std::optional<std::string> shadowed_file_note(const std::string& name_or_path);

}  // namespace resecto
