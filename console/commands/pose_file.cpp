// Pose lines for `resecto collide`, checked at the edge: finite, rigid, within reach.
#include "console/commands/pose_file.h"

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <optional>
#include <string>
#include <string_view>

#include <glm/matrix.hpp>

#include "rtcore/base/checked_number.h"
#include "rtcore/base/text_file.h"

namespace resecto::cli {

namespace {

/// "nan", "inf", "-Infinity" and the like: a number, but not a finite one.
bool names_a_non_finite_number(std::string_view word) {
  if (!word.empty() && (word.front() == '+' || word.front() == '-')) word.remove_prefix(1);
  std::string lower(word.substr(0, 3));
  for (char& c : lower) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return lower == "nan" || lower == "inf";
}

}  // namespace

Result<std::vector<RigidPose>> parse_poses(const std::string& text, const std::string& source) {
  std::vector<RigidPose> poses;
  int number = 0;
  // Lines end in LF, CR LF or a lone CR (text_lines).
  for (std::string_view text_line : text_lines(text)) {
    ++number;
    // A comment runs from '#' to the end of the line, as in procedure files (audit 32, F12: one after
    // the numbers was read as a thirteenth).
    if (const std::size_t comment = text_line.find('#'); comment != std::string_view::npos) text_line = text_line.substr(0, comment);
    const std::vector<TextWord> words = text_words(text_line, ",");
    if (words.empty()) continue;
    const std::string line_place = source + ":" + std::to_string(number) + ": ";
    double values[12];
    int count = 0;
    for (const TextWord& word : words) {
      const std::string where = source + ":" + std::to_string(number) + ":" + std::to_string(word.column) + ": ";
      // Decimal numbers only, as the mesh readers and the procedure files take them: strtod also took
      // hexadecimal ("0x3") and read the number at the front of a word ("1.5abc").
      const std::optional<double> v = parse_finite(word.text);
      if (!v && names_a_non_finite_number(word.text)) {
        return Error{where + "number " + std::to_string(count + 1) + " of 12, '" + std::string(word.text) + "', is not finite"};
      }
      if (!v) return Error{where + "'" + std::string(word.text.substr(0, 20)) + "' is not a number"};
      if (count == 12) return Error{where + "more than 12 numbers (expected r00 r01 r02 tx r10 r11 r12 ty r20 r21 r22 tz)"};
      values[count++] = *v;
    }
    const std::string& where = line_place;
    if (count != 12) {
      return Error{where + "expected 12 numbers (r00 r01 r02 tx r10 r11 r12 ty r20 r21 r22 tz), found " + std::to_string(count)};
    }
    std::array<double, 12> row_major{};
    std::copy(values, values + 12, row_major.begin());
    const RigidPose pose = from_row_major_3x4(row_major);
    for (int i = 0; i < 3; ++i) {
      if (!in_closed_range(pose.translation[i], -kMaxPoseTranslation, kMaxPoseTranslation)) {
        return Error{where + "translation " + exact_number(pose.translation[i]) + " is outside [" + exact_number(-kMaxPoseTranslation) +
                     ", " + exact_number(kMaxPoseTranslation) + "]"};
      }
    }
    if (const double defect = orthonormality_error(pose.rotation); !(defect <= 1e-4)) {
      return Error{where + "the 3x3 rotation is not orthonormal (R^T R is off the identity by " + rounded_number(defect, 3) +
                   " in an entry; 1e-4 is the most taken)"};
    }
    const double det = glm::determinant(pose.rotation);
    if (!(det > 0.0)) return Error{where + "the 3x3 rotation is a reflection (determinant " + exact_number(det) + "), not a rotation"};
    poses.push_back(pose);
  }
  if (poses.empty()) return Error{source + ": no poses (12 numbers a line)"};
  return poses;
}

}  // namespace resecto::cli
