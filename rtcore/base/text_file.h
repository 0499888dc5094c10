// Reading a whole text file for a parser that names its errors by the file's path. Header-only so
// every module can use it, whatever it links.
#pragma once

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "rtcore/base/result.h"

namespace resecto {

/// The file's bytes, or an error "<path>: cannot open<what>".
inline Result<std::string> read_text_file(const std::filesystem::path& path, const std::string& what = "") {
  std::ifstream in(path, std::ios::binary);
  if (!in) return Error{path.string() + ": cannot open" + what};
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

}  // namespace resecto
