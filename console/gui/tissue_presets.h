// Tissue parameter presets: every `resecto params` value in a small JSON file, so an instructor saves
// the tissue they tuned and loads it again (`resecto console --preset FILE`, the parameters panel,
// `preset save|load` actions). {"resecto_preset": 1, "parameters": {"stiffness": 40, ...}} in the
// parameters' own units; a preset may name only some parameters.
#pragma once

#include <filesystem>

#include "rtcore/base/result.h"
#include "rtcore/tissue/tissue_parameters.h"

namespace resecto::gui {

/// Writes all parameters (temporary file, then rename).
Status save_preset(const std::filesystem::path& path, const TissueParameters& parameters);
/// Reads a preset over `base`: unknown keys, bad values and values out of range are errors that name
/// the file and the key.
Result<TissueParameters> load_preset(const std::filesystem::path& path, const TissueParameters& base);

}  // namespace resecto::gui
