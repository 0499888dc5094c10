// Parsing a JSON input whose syntax errors name where they are: "<source>: not valid JSON at line L,
// column C: <what the parser expected>", without the library's own prefix. Header-only, as the
// modules that read JSON (anatomy, device, console) link nlohmann_json themselves.
#pragma once

#include <string>

#include <nlohmann/json.hpp>

#include "rtcore/base/result.h"
#include "rtcore/base/text_file.h"

namespace resecto {

/// The library's message without its "[json.exception.NAME.ID] " prefix.
inline std::string library_free(const std::string& what) {
  if (what.starts_with("[json.exception.")) {
    if (const std::size_t end = what.find("] "); end != std::string::npos) return what.substr(end + 2);
  }
  return what;
}

inline Result<nlohmann::json> parse_json_text(const std::string& text, const std::string& source) {
  try {
    return nlohmann::json::parse(text);
  } catch (const nlohmann::json::parse_error& e) {
    // e.byte counts the bytes read, the offending one included; what() is
    // "[json.exception.parse_error.101] parse error at line 1, column 2: syntax error while parsing ...".
    std::string why = library_free(e.what());
    if (const std::size_t colon = why.find(": "); colon != std::string::npos) why = why.substr(colon + 2);
    return Error{source + ": not valid JSON at " + text_position(text, e.byte == 0 ? 0 : e.byte - 1) + ": " + why};
  } catch (const nlohmann::json::exception& e) {  // e.g. out_of_range 406: a number past a double's range
    return Error{source + ": not valid JSON: " + library_free(e.what())};
  }
}

}  // namespace resecto
