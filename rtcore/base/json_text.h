// Parsing a JSON input whose syntax errors name where they are: "<source>: not valid JSON at line L,
// column C: <what the parser expected>", without the library's own prefix. Header-only, as the
// modules that read JSON (anatomy, device, console) link nlohmann_json themselves.
#pragma once

#include <functional>
#include <optional>
#include <set>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "rtcore/base/quoted_word.h"
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

/// The most levels of arrays and objects a JSON input may nest. Every file this program reads nests a
/// handful; the library parses any depth, but copying or walking a document 50,000 levels deep
/// recurses that deep and overflows the stack (audit 32, F1: a crafted recording header).
inline constexpr std::size_t kMostJsonNesting = 256;

/// Where `text` first opens a level of arrays and objects past kMostJsonNesting (brackets inside
/// strings do not count), or std::string::npos.
inline std::size_t json_nesting_overflow(std::string_view text) {
  std::size_t depth = 0;
  bool in_string = false, escaped = false;
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (in_string) {
      if (escaped) escaped = false;
      else if (c == '\\') escaped = true;
      else if (c == '"') in_string = false;
    } else if (c == '"') {
      in_string = true;
    } else if (c == '[' || c == '{') {
      if (++depth > kMostJsonNesting) return i;
    } else if ((c == ']' || c == '}') && depth > 0) {
      --depth;
    }
  }
  return std::string::npos;
}

/// The error for JSON `text` from `source` that nests too deep, or nothing.
inline std::optional<std::string> json_nesting_error(std::string_view text, const std::string& source) {
  const std::size_t at = json_nesting_overflow(text);
  if (at == std::string::npos) return std::nullopt;
  return source + ": nests arrays and objects more than " + std::to_string(kMostJsonNesting) + " levels deep at " + text_position(text, at);
}

namespace detail {

/// Follows the parser through a document (nlohmann's parse callback) and keeps the path of the first
/// key an object names twice, "sheath.offset_mm" or "points[2].x", or nothing.
class RepeatedKeyFinder {
 public:
  bool operator()(int /*depth*/, nlohmann::json::parse_event_t event, const nlohmann::json& parsed) {
    using Event = nlohmann::json::parse_event_t;
    switch (event) {
      case Event::object_start:
        levels_.push_back({true, {}, {}, 0});
        break;
      case Event::array_start:
        levels_.push_back({false, {}, {}, 0});
        break;
      case Event::key: {
        Level& object = levels_.back();
        object.key = parsed.get<std::string>();
        if (!object.keys.insert(object.key).second && repeated_.empty()) repeated_ = path();
        break;
      }
      case Event::object_end:
      case Event::array_end:
        levels_.pop_back();
        element_done();
        break;
      case Event::value:
        element_done();
        break;
    }
    return true;  // keep everything: the document is still built whole
  }
  const std::string& repeated() const { return repeated_; }

 private:
  struct Level {
    bool object;
    std::set<std::string> keys;  // an object's keys so far
    std::string key;             // an object's current key
    std::size_t index;           // an array's current element
  };
  void element_done() {
    if (!levels_.empty() && !levels_.back().object) ++levels_.back().index;
  }
  std::string path() const {
    std::string out;
    // Appended piece by piece: `"[" + std::to_string(...)` trips GCC 12's false -Wrestrict at -O3.
    for (const Level& level : levels_) {
      if (!level.object) {
        out.append("[").append(std::to_string(level.index)).append("]");
      } else {
        if (!out.empty()) out.push_back('.');
        out.append(printable_text(level.key));
      }
    }
    return out;
  }

  std::vector<Level> levels_;
  std::string repeated_;
};

}  // namespace detail

/// The document in `text`, or an error naming `source` and where the syntax fails. With
/// `refuse_repeated_keys`, an object that names a key twice is an error naming the key's path: the
/// library keeps the last silently, so a hand-edited file could be read with a value its author
/// thought was replaced.
inline Result<nlohmann::json> parse_json_text(const std::string& text, const std::string& source, bool refuse_repeated_keys = false) {
  if (std::optional<std::string> deep = json_nesting_error(text, source)) return Error{*deep};
  try {
    if (refuse_repeated_keys) {
      detail::RepeatedKeyFinder finder;
      nlohmann::json document = nlohmann::json::parse(text, std::ref(finder));
      if (!finder.repeated().empty()) return Error{source + ": " + finder.repeated() + ": the key appears twice in its object"};
      return document;
    }
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
