// The landmarks file's channel axis, checked field by field with the field's JSON path in errors.
#include "rtcore/anatomy/landmarks_file.h"

#include <cmath>

#include <nlohmann/json.hpp>

#include "rtcore/base/checked_number.h"
#include "rtcore/base/json_text.h"

namespace resecto {

Result<std::pair<Vec3, Vec3>> parse_channel_axis(const std::string& text, const std::string& source) {
  Result<nlohmann::json> parsed = parse_json_text(text, source);
  if (!parsed) return Error{parsed.error()};
  const nlohmann::json& doc = *parsed;
  if (!doc.is_object() || !doc.contains("channel_axis") || !doc["channel_axis"].is_object()) {
    return Error{source + ": channel_axis: missing (an object with apex and bladder_neck)"};
  }
  // The file says its unit; a file in another would be read a thousandfold off (audit 29, F13).
  if (doc.contains("units") && !(doc["units"].is_string() && doc["units"].get<std::string>() == "mm")) {
    return Error{source + ": units: " + doc["units"].dump() + " (only \"mm\" is read: the coordinates are millimetres)"};
  }
  const nlohmann::json& axis = doc["channel_axis"];
  Vec3 points[2];
  const char* names[2] = {"apex", "bladder_neck"};
  for (int i = 0; i < 2; ++i) {
    const std::string field = std::string("channel_axis.") + names[i];
    if (!axis.contains(names[i]) || !axis[names[i]].is_array() || axis[names[i]].size() != 3) {
      return Error{source + ": " + field + ": must be 3 numbers (millimetres)"};
    }
    double xyz[3];
    for (std::size_t k = 0; k < 3; ++k) {
      const nlohmann::json& value = axis[names[i]][k];
      if (!value.is_number()) return Error{source + ": " + field + "[" + std::to_string(k) + "]: not a number"};
      xyz[k] = value.get<double>();
      if (auto problem = range_problem(field + "[" + std::to_string(k) + "]", xyz[k], -kMaxLandmarkMm, kMaxLandmarkMm)) {
        return Error{source + ": " + *problem + " mm"};
      }
    }
    points[i] = Vec3(xyz[0], xyz[1], xyz[2]);
  }
  const Vec3 d = points[1] - points[0];
  if (!(std::sqrt(d.x * d.x + d.y * d.y + d.z * d.z) >= kMinChannelLengthMm)) {
    return Error{source + ": channel_axis: apex and bladder_neck are less than " + exact_number(kMinChannelLengthMm) + " mm apart"};
  }
  return std::make_pair(points[0] * 1e-3, points[1] * 1e-3);
}

}  // namespace resecto
