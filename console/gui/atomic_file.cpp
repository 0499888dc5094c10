// Temporary file, then rename.
#include "console/gui/atomic_file.h"

#include <fstream>
#include <string>
#include <system_error>

namespace resecto::gui {

Status write_text_atomically(const std::filesystem::path& path, std::string_view text, std::string_view what) {
  const std::filesystem::path temporary = path.string() + ".tmp";
  {
    std::ofstream out(temporary, std::ios::binary);
    out.write(text.data(), static_cast<std::streamsize>(text.size()));
    if (!out.flush()) return Error{path.string() + ": cannot write the " + std::string(what)};
  }
  std::error_code error;
  std::filesystem::rename(temporary, path, error);
  if (error) return Error{path.string() + ": cannot move the " + std::string(what) + " into place: " + error.message()};
  return Ok{};
}

}  // namespace resecto::gui
