// Preset files.
#include "console/gui/tissue_presets.h"

#include <string>

#include <nlohmann/json.hpp>

#include "rtcore/base/atomic_file.h"
#include "rtcore/base/json_text.h"
#include "rtcore/base/quoted_word.h"
#include "rtcore/base/text_file.h"

namespace resecto::gui {

Status save_preset(const std::filesystem::path& path, const TissueParameters& parameters) {
  nlohmann::ordered_json preset;
  preset["resecto_preset"] = 1;
  for (const TissueParameterSpec& spec : tissue_parameter_specs()) {
    preset["parameters"][std::string(spec.key)] = parameters.get(spec.id);
  }
  return write_file_atomically(path, preset.dump(2) + "\n");
}

Result<TissueParameters> load_preset(const std::filesystem::path& path, const TissueParameters& base) {
  Result<std::string> text = read_utf8_text_file(path, " the preset");
  if (!text) return Error{text.error()};
  // A key written twice (a hand edit) is refused as in calibration files: the library would keep the last silently.
  Result<nlohmann::json> parsed = parse_json_text(*text, path.string(), true);
  if (!parsed) return Error{parsed.error()};
  const nlohmann::json& preset = *parsed;
  if (!preset.is_object()) return Error{path.string() + ": not a JSON object (a preset is {\"resecto_preset\": 1, \"parameters\": {...}})"};
  if (!preset.contains("resecto_preset")) return Error{path.string() + ": not a Resecto preset (\"resecto_preset\": 1 is missing)"};
  if (preset["resecto_preset"] != 1) {
    return Error{path.string() + ": preset format " + preset["resecto_preset"].dump() + " is not one this build reads (it reads format 1)"};
  }
  for (const auto& [key, value] : preset.items()) {
    if (key != "resecto_preset" && key != "parameters") {
      return Error{path.string() + ": unknown key " + quoted_word(key) + " (a preset holds \"resecto_preset\" and \"parameters\")"};
    }
  }
  if (!preset.contains("parameters") || !preset["parameters"].is_object()) {
    return Error{path.string() + ": \"parameters\" must be an object of key: value"};
  }
  TissueParameters result = base;
  for (const auto& [key, value] : preset["parameters"].items()) {
    const std::optional<TissueParameter> id = find_tissue_parameter(key);
    // Quoted: a key holding a NUL cut the message short, an escape sequence reached the terminal (audit 8, G13).
    if (!id) return Error{path.string() + ": unknown parameter " + quoted_word(key) + " (see resecto params)"};
    if (!value.is_number()) return Error{path.string() + ": parameter " + quoted_word(key) + " must be a number"};
    if (Status set = result.set(*id, value.get<double>()); !set) return Error{path.string() + ": " + set.error()};
  }
  return result;
}

}  // namespace resecto::gui
