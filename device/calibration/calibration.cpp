// The calibration file: JSON in millimetres, read with errors naming the field, written atomically.
#include "device/calibration/calibration.h"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <optional>
#include <sstream>

#include <nlohmann/json.hpp>

#include "resecto/lp3500_sensors.h"
#include "rtcore/base/atomic_file.h"
#include "rtcore/base/checked_number.h"
#include "rtcore/base/json_text.h"
#include "rtcore/base/quoted_word.h"
#include "rtcore/base/text_file.h"
#include "rtcore/base/units.h"
#include "rtcore/geometry/rigid_pose.h"

namespace resecto::device {
namespace {

using nlohmann::json;

constexpr const char* kFormat = "resecto-calibration";
constexpr int kVersion = 1;

/// Walks a JSON document, remembering the first failure with the dotted path of the field at fault.
class FieldReader {
 public:
  FieldReader(const json& root, std::string source) : root_(root), source_(std::move(source)) {}

  const json* at(const std::string& path) {
    const json* node = &root_;
    std::string::size_type start = 0;
    while (start <= path.size()) {
      const auto dot = path.find('.', start);
      const std::string key = path.substr(start, dot == std::string::npos ? std::string::npos : dot - start);
      if (!node->is_object() || !node->contains(key)) return fail(path, "missing"), nullptr;
      node = &(*node)[key];
      if (dot == std::string::npos) break;
      start = dot + 1;
    }
    return node;
  }

  double number(const std::string& path) {
    const json* node = at(path);
    if (!node) return 0.0;
    if (!node->is_number()) return fail(path, "not a number"), 0.0;
    const double value = node->get<double>();
    if (!std::isfinite(value)) return fail(path, "not finite"), 0.0;
    return value;
  }

  /// A numeric array of exactly `count` entries.
  std::vector<double> numbers(const std::string& path, size_t count) {
    const json* node = at(path);
    if (!node) return {};
    if (!node->is_array() || node->size() != count) {
      return fail(path, "must be an array of " + std::to_string(count) + " numbers"), std::vector<double>{};
    }
    std::vector<double> values;
    for (size_t i = 0; i < count; ++i) {
      if (!(*node)[i].is_number()) return fail(path + "[" + std::to_string(i) + "]", "not a number"), std::vector<double>{};
      values.push_back((*node)[i].get<double>());
    }
    return values;
  }

  /// Refuses a key of the object at `path` ("" for the document) that is none of `known`: a misspelt
  /// key is otherwise ignored, and the field it meant keeps the value it had.
  void only_keys(const std::string& path, std::initializer_list<const char*> known) {
    const json* node = path.empty() ? &root_ : at(path);
    if (!node || !node->is_object()) return;
    std::string names;
    for (const char* name : known) names += std::string(names.empty() ? "" : ", ") + name;
    for (const auto& [key, value] : node->items()) {
      const bool found = std::any_of(known.begin(), known.end(), [&](const char* name) { return key == name; });
      const std::string field = printable_text(key);
      if (!found)
        fail(path.empty() ? field : path + "." + field, "unknown key (" + (path.empty() ? "the file" : path) + " holds " + names + ")");
    }
  }

  void fail(const std::string& path, const std::string& why) {
    if (error_.empty()) error_ = source_ + ": " + path + ": " + why;
  }
  bool ok() const { return error_.empty(); }
  const std::string& error() const { return error_; }

 private:
  const json& root_;
  std::string source_;
  std::string error_;
};

/// The largest registration translation read, in mm on each axis.
constexpr double kMaxTranslationMm = units::m_to_mm(kRegistrationReachM);

bool is_whole(double v, double lo, double hi) { return v == std::floor(v) && v >= lo && v <= hi; }

/// The keys a calibration file holds, object by object.
void refuse_unknown_keys(FieldReader& in) {
  in.only_keys("", {"format", "version", "sheath", "hall_table", "encoders", "registration"});
  in.only_keys("sheath", {"gain_mm_per_count", "offset_mm", "min_mm", "max_mm"});
  in.only_keys("hall_table", {"hall_sum_counts", "loop_mm"});
  in.only_keys("encoders", {"counts_per_revolution"});
  in.only_keys("registration", {"rotation", "translation_mm"});
}

/// Why the sensor models cannot describe the device, or nothing. The board clamps the sheath's reading
/// to [min_mm, max_mm], so a model mapping every potentiometer count outside that range reads one end
/// whatever the sheath does; a Hall table point is a loop position measured, so it lies on the loop's
/// travel. For a calibration the board takes (to_board): its gain is non-zero and min_mm below max_mm.
std::optional<std::string> sensor_model_problem(const Calibration& c) {
  const double at_zero = c.sheath_offset_mm, at_max = c.sheath_gain_mm_per_count * kAdcMaxCounts + c.sheath_offset_mm;
  const double lo = std::min(at_zero, at_max), hi = std::max(at_zero, at_max);
  if (!(hi >= c.sheath_min_mm && lo <= c.sheath_max_mm)) {
    return "sheath: potentiometer counts 0-" + exact_number(kAdcMaxCounts) + " map to " + rounded_number(lo, 9) + " .. " +
           rounded_number(hi, 9) + " mm, all outside the sheath's travel (min_mm " + exact_number(c.sheath_min_mm) + " to max_mm " +
           exact_number(c.sheath_max_mm) + "): gain_mm_per_count or offset_mm is wrong";
  }
  for (unsigned i = 0; i < LP3500_HALL_TABLE_POINTS; ++i) {
    if (!in_closed_range(c.loop_mm[i], 0.0, kLoopTravelMm)) {
      return "hall_table.loop_mm[" + std::to_string(i) + "]: " + exact_number(c.loop_mm[i]) + " mm is outside the loop's 0-" +
             exact_number(kLoopTravelMm) + " mm travel";
    }
  }
  return std::nullopt;
}

/// Which of the board's sheath rules `b` (from `c`) breaks: the board answers only that one is.
std::string sheath_rule_broken(const Calibration& c, const lp3500_calibration& b) {
  if (b.sheath_gain_nm_per_count == 0) {
    return "sheath.gain_mm_per_count: " + exact_number(c.sheath_gain_mm_per_count) +
           " is zero to the board's 0.000001 mm per count, and a zero gain reads every count as offset_mm";
  }
  if (b.sheath_min_um >= b.sheath_max_um) {
    return "sheath: min_mm " + exact_number(c.sheath_min_mm) + " must be below max_mm " + exact_number(c.sheath_max_mm);
  }
  return "sheath.gain_mm_per_count: " + exact_number(c.sheath_gain_mm_per_count) + " is outside +-0.5 mm per count";
}

}  // namespace

Calibration default_calibration() { return from_board(lp3500_default_calibration, Calibration{}); }

Calibration from_board(const lp3500_calibration& board, const Calibration& base) {
  Calibration c = base;
  c.sheath_gain_mm_per_count = board.sheath_gain_nm_per_count * 1e-6;
  c.sheath_offset_mm = board.sheath_offset_um * 1e-3;
  c.sheath_min_mm = board.sheath_min_um * 1e-3;
  c.sheath_max_mm = board.sheath_max_um * 1e-3;
  for (unsigned i = 0; i < LP3500_HALL_TABLE_POINTS; ++i) {
    c.hall_sum_counts[i] = board.hall_sum[i];
    c.loop_mm[i] = board.loop_um[i] * 1e-3;
  }
  return c;
}

Result<lp3500_calibration> to_board(const Calibration& c) {
  lp3500_calibration b{};
  auto to_int32 = [](double v, double scale, const char* field, int32_t& out) -> std::string {
    const double scaled = std::round(v * scale);
    if (!(std::abs(scaled) < 2147483647.0)) return std::string(field) + ": out of range";
    out = static_cast<int32_t>(scaled);
    return {};
  };
  for (const std::string& e : {to_int32(c.sheath_gain_mm_per_count, 1e6, "sheath.gain_mm_per_count", b.sheath_gain_nm_per_count),
                               to_int32(c.sheath_offset_mm, 1e3, "sheath.offset_mm", b.sheath_offset_um),
                               to_int32(c.sheath_min_mm, 1e3, "sheath.min_mm", b.sheath_min_um),
                               to_int32(c.sheath_max_mm, 1e3, "sheath.max_mm", b.sheath_max_um)}) {
    if (!e.empty()) return Error{e};
  }
  for (unsigned i = 0; i < LP3500_HALL_TABLE_POINTS; ++i) {
    const double um = std::round(c.loop_mm[i] * 1e3);
    if (!(um >= 0.0 && um <= 65535.0)) {
      return Error{"hall_table.loop_mm[" + std::to_string(i) + "]: outside 0-65.535 mm"};
    }
    b.loop_um[i] = static_cast<uint16_t>(um);
    b.hall_sum[i] = c.hall_sum_counts[i];
  }
  int bad = -1;
  switch (lp3500_validate_calibration(&b, &bad)) {
    case LP3500_OK: return b;
    case LP3500_ERROR_SHEATH_RANGE:
      return Error{sheath_rule_broken(c, b)};
    case LP3500_ERROR_NOT_MONOTONE:
      return Error{"hall_table[" + std::to_string(bad) + "]: hall_sum_counts must be strictly monotone and loop_mm "
                   "strictly increasing (points " + std::to_string(bad - 1) + " and " + std::to_string(bad) + ")"};
    default: return Error{"calibration refused by the board's rules"};
  }
}

Result<Calibration> parse_calibration(const std::string& text, const std::string& source) {
  Result<json> parsed = parse_json_text(text, source, true);
  if (!parsed) return Error{parsed.error()};
  const json& root = *parsed;
  FieldReader in(root, source);
  Calibration c;
  if (const json* format = in.at("format"); format && (!format->is_string() || *format != kFormat)) {
    in.fail("format", std::string("must be \"") + kFormat + "\"");
  }
  if (const double version = in.number("version"); in.ok() && version != kVersion) {
    in.fail("version", "unsupported (this build reads version 1)");
  }
  c.sheath_gain_mm_per_count = in.number("sheath.gain_mm_per_count");
  c.sheath_offset_mm = in.number("sheath.offset_mm");
  c.sheath_min_mm = in.number("sheath.min_mm");
  c.sheath_max_mm = in.number("sheath.max_mm");
  const auto sums = in.numbers("hall_table.hall_sum_counts", LP3500_HALL_TABLE_POINTS);
  const auto loops = in.numbers("hall_table.loop_mm", LP3500_HALL_TABLE_POINTS);
  const auto cpr = in.numbers("encoders.counts_per_revolution", LP3500_ENCODER_COUNT);
  const json* rotation = in.at("registration.rotation");
  const auto translation = in.numbers("registration.translation_mm", 3);
  refuse_unknown_keys(in);
  if (!in.ok()) return Error{in.error()};
  for (unsigned i = 0; i < LP3500_HALL_TABLE_POINTS; ++i) {
    if (!is_whole(sums[i], 0, 8190)) in.fail("hall_table.hall_sum_counts[" + std::to_string(i) + "]", "not a whole number in 0-8190");
    c.hall_sum_counts[i] = static_cast<uint16_t>(sums[i]);
    c.loop_mm[i] = loops[i];
  }
  for (unsigned a = 0; a < LP3500_ENCODER_COUNT; ++a) {
    // An optical encoder that counts fewer than 100 a turn places a joint to 3.6 degrees or worse: a
    // typing slip (the reference device's 4096), which would swing the tool through the tissue.
    if (!is_whole(cpr[a], 100, 1e9)) {
      in.fail("encoders.counts_per_revolution[" + std::to_string(a) + "]", "not a whole number in 100-1000000000 (the reference device counts 4096)");
    }
    c.encoder_counts_per_revolution[a] = static_cast<int>(cpr[a]);
  }
  bool rotation_shape = rotation->is_array() && rotation->size() == 3;
  for (unsigned r = 0; rotation_shape && r < 3; ++r) {
    const json& row = (*rotation)[r];
    rotation_shape = row.is_array() && row.size() == 3;
    for (unsigned k = 0; rotation_shape && k < 3; ++k) {
      rotation_shape = row[k].is_number();
      if (rotation_shape) c.rotation[r][k] = row[k].get<double>();
    }
  }
  if (!rotation_shape) in.fail("registration.rotation", "must be 3 rows of 3 numbers (row-major)");
  // The registration places the device within reach of the patient: a metre either way is generous.
  for (unsigned k = 0; k < 3; ++k) {
    c.translation_mm[k] = translation[k];
    const std::string field = "registration.translation_mm[" + std::to_string(k) + "]";
    if (!in_closed_range(translation[k], -kMaxTranslationMm, kMaxTranslationMm)) {
      in.fail(field, exact_number(translation[k]) + " is outside [" + exact_number(-kMaxTranslationMm) + ", " + exact_number(kMaxTranslationMm) + "] mm");
    }
  }
  if (!in.ok()) return Error{in.error()};
  glm::dmat3 matrix;  // glm is column-major: matrix[column][row]
  for (unsigned r = 0; r < 3; ++r) {
    for (unsigned k = 0; k < 3; ++k) matrix[k][r] = c.rotation[r][k];
  }
  if (!is_proper_rotation(matrix)) return Error{source + ": registration.rotation: not a proper rotation (orthonormal, det +1)"};
  const auto board = to_board(c);
  if (!board) return Error{source + ": " + board.error()};
  if (auto problem = sensor_model_problem(c)) return Error{source + ": " + *problem};
  return c;
}

Result<Calibration> read_calibration(const std::filesystem::path& path) {
  Result<std::string> text = read_utf8_text_file(path);
  if (!text) return Error{text.error()};
  return parse_calibration(*text, path.string());
}

std::string calibration_to_json(const Calibration& c) {
  json j;
  j["format"] = kFormat;
  j["version"] = kVersion;
  j["sheath"] = {{"gain_mm_per_count", c.sheath_gain_mm_per_count},
                 {"offset_mm", c.sheath_offset_mm},
                 {"min_mm", c.sheath_min_mm},
                 {"max_mm", c.sheath_max_mm}};
  j["hall_table"] = {{"hall_sum_counts", c.hall_sum_counts}, {"loop_mm", c.loop_mm}};
  j["encoders"] = {{"counts_per_revolution", c.encoder_counts_per_revolution}};
  j["registration"] = {{"rotation", c.rotation}, {"translation_mm", c.translation_mm}};
  return j.dump(2) + "\n";
}

Status write_calibration(const Calibration& calibration, const std::filesystem::path& path) {
  return write_file_atomically(path, calibration_to_json(calibration));
}

}  // namespace resecto::device
