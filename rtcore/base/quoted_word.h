// A word from an input file, quoted for an error message that names it: at most 24 bytes (a long
// one ends in "..."), and control bytes written as \xNN, since a NUL cut the printed message short.
// printable_text does the second alone, for a name printed whole (a JSON key in a field's path).
#pragma once

#include <string>
#include <string_view>

namespace resecto {

/// `text` with its control bytes written as \xNN, so that a message naming it stays one printable line.
inline std::string printable_text(std::string_view text) {
  std::string out;
  for (const char c : text) {
    const auto byte = static_cast<unsigned char>(c);
    if (byte >= 0x20 && byte != 0x7f) {
      out.push_back(c);
      continue;
    }
    constexpr char kHex[] = "0123456789abcdef";
    out += "\\x";
    out.push_back(kHex[byte >> 4]);
    out.push_back(kHex[byte & 15]);
  }
  return out;
}

inline std::string quoted_word(std::string_view word) {
  // Appended, not `"'" + std::string(...)`: GCC 12 at -O3 warns falsely (-Wrestrict) on that form.
  std::string text = "'";
  text += printable_text(word.substr(0, 24));
  text += word.size() > 24 ? "...'" : "'";
  return text;
}

}  // namespace resecto
