// Writing a file so a reader never sees half of it: the text goes to a temporary file beside it,
// which is then renamed over the target. The console's presets and session reports use it.
#pragma once

#include <filesystem>
#include <string_view>

#include "rtcore/base/result.h"

namespace resecto::gui {

/// Writes `text` to `path` atomically; the error names the path and what failed.
Status write_text_atomically(const std::filesystem::path& path, std::string_view text, std::string_view what);

}  // namespace resecto::gui
