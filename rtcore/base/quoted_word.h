// A word from an input file, quoted for an error message that names it: at most 24 bytes (a long
// one ends in "..."), and control bytes written as \xNN, since a NUL cut the printed message short.
#pragma once

#include <string>
#include <string_view>

namespace resecto {

inline std::string quoted_word(std::string_view word) {
  // Appended, not `"'" + std::string(...)`: GCC 12 at -O3 warns falsely (-Wrestrict) on that form.
  std::string text = "'";
  for (const char c : word.substr(0, 24)) {
    const auto byte = static_cast<unsigned char>(c);
    if (byte >= 0x20 && byte != 0x7f) {
      text.push_back(c);
      continue;
    }
    constexpr char kHex[] = "0123456789abcdef";
    text += "\\x";
    text.push_back(kHex[byte >> 4]);
    text.push_back(kHex[byte & 15]);
  }
  text += word.size() > 24 ? "...'" : "'";
  return text;
}

}  // namespace resecto
