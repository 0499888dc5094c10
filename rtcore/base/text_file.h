// Reading a whole input file for a parser that names its errors by the file's path. Only regular
// files are read, and only up to a cap, so a device (/dev/urandom), a pipe or a huge file gets an
// error instead of an endless read. Header-only so every module can use it, whatever it links.
#pragma once

#include <algorithm>
#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <system_error>
#include <vector>

#include "rtcore/base/result.h"

namespace resecto {

/// The largest text input (procedure, poses, calibration, CSV, landmarks) read whole: 64 MiB.
inline constexpr std::uintmax_t kMaxTextFileBytes = std::uintmax_t{64} << 20;

/// The largest binary input (a recording) read whole: 8 GiB, a third of a large workstation's memory.
inline constexpr std::uintmax_t kMaxBinaryFileBytes = std::uintmax_t{8} << 30;

/// The size of the regular file at `path`, or why it is not one to read: missing (or a link to
/// nothing), a folder, a device or pipe, over `max_bytes`. `what` as read_regular_file's.
inline Result<std::uintmax_t> regular_file_size(const std::filesystem::path& path, const std::string& what, std::uintmax_t max_bytes) {
  const std::string name = path.string();
  std::error_code ec;
  const std::filesystem::file_status status = std::filesystem::status(path, ec);
  if (status.type() == std::filesystem::file_type::not_found) {
    // A link that leads nowhere is there, and "no such file" sent users looking for a typo.
    std::error_code link_error;
    const bool dangling = std::filesystem::is_symlink(std::filesystem::symlink_status(path, link_error));
    return Error{name + ": cannot open" + what + (dangling ? ": a symbolic link whose target is missing" : ": no such file")};
  }
  if (ec) return Error{name + ": cannot open" + what + ": " + ec.message()};
  if (status.type() == std::filesystem::file_type::directory) return Error{name + ": is a folder, not a file"};
  if (status.type() != std::filesystem::file_type::regular) {
    return Error{name + ": not a regular file (a device or pipe is never read whole)"};
  }
  const std::uintmax_t size = std::filesystem::file_size(path, ec);
  if (ec) return Error{name + ": cannot open" + what + ": " + ec.message()};
  if (size > max_bytes) {
    return Error{name + ": " + std::to_string(size) + " bytes, more than the " + std::to_string(max_bytes) + "-byte limit for this input"};
  }
  return size;
}

/// The file's bytes in `Bytes` (std::string, std::vector<std::uint8_t>), or an error "<path>: <why>"
/// (missing, a folder, not a regular file, over `max_bytes`, unreadable). `what` names the file's
/// role in the open error, e.g. " the procedure file".
template <class Bytes>
Result<Bytes> read_regular_file(const std::filesystem::path& path, const std::string& what, std::uintmax_t max_bytes) {
  const std::string name = path.string();
  const Result<std::uintmax_t> checked = regular_file_size(path, what, max_bytes);
  if (!checked) return Error{checked.error()};
  const std::uintmax_t size = *checked;
  std::FILE* file = std::fopen(name.c_str(), "rb");
  if (file == nullptr) return Error{name + ": cannot open" + what + ": " + std::strerror(errno)};  // e.g. "Permission denied"
  // Read at most one byte past the size seen: a file that grows meanwhile is cut, never read forever.
  Bytes bytes(static_cast<std::size_t>(size) + 1, 0);
  const std::size_t got = std::fread(bytes.data(), 1, bytes.size(), file);
  const bool failed = std::ferror(file) != 0;
  std::fclose(file);
  if (failed) return Error{name + ": read failed"};
  if (got > size) return Error{name + ": changed size while it was read"};
  bytes.resize(got);
  return bytes;
}

/// A text input read whole (read_regular_file), up to `max_bytes`.
inline Result<std::string> read_text_file(const std::filesystem::path& path, const std::string& what = "",
                                          std::uintmax_t max_bytes = kMaxTextFileBytes) {
  return read_regular_file<std::string>(path, what, max_bytes);
}

/// A place in a text: its line and its column, counting bytes, both from 1.
struct TextPlace {
  std::size_t line = 1;
  std::size_t column = 1;
};

/// The place of the byte at `offset` (from 0) of `text`.
inline TextPlace text_place(std::string_view text, std::size_t offset) {
  offset = std::min(offset, text.size());
  std::size_t line = 1, line_start = 0;
  for (std::size_t i = 0; i < offset; ++i) {
    if (text[i] == '\n') ++line, line_start = i + 1;
  }
  return {line, offset - line_start + 1};
}

/// "line L, column C" (from 1) of the byte at `offset` (from 0) of `text`, for a parser that reports
/// where it stopped as a byte count (nlohmann::json's parse_error::byte is the count read, from 1).
inline std::string text_position(std::string_view text, std::size_t offset) {
  const TextPlace place = text_place(text, offset);
  return "line " + std::to_string(place.line) + ", column " + std::to_string(place.column);
}

/// The lines of `text`, ended by "\n", "\r\n" or a lone "\r" (classic Mac OS files, and some
/// spreadsheets' exports, end lines with CR alone: read by "\n" they were one long line), without
/// their endings. A last line without an ending counts; an ending at the very end adds no empty line.
inline std::vector<std::string_view> text_lines(std::string_view text) {
  std::vector<std::string_view> lines;
  std::size_t start = 0;
  for (std::size_t i = 0; i < text.size(); ++i) {
    if (text[i] != '\n' && text[i] != '\r') continue;
    lines.push_back(text.substr(start, i - start));
    if (text[i] == '\r' && i + 1 < text.size() && text[i + 1] == '\n') ++i;
    start = i + 1;
  }
  if (start < text.size()) lines.push_back(text.substr(start));
  return lines;
}

/// A word of a line and where it starts: its column, counting bytes from 1.
struct TextWord {
  std::string_view text;
  std::size_t column = 1;
};

/// The words of `line`, split on spaces, tabs, vertical tabs and form feeds, and on any of `separators`
/// (",": the procedure and pose files take commas between numbers, as a spreadsheet exports them).
inline std::vector<TextWord> text_words(std::string_view line, std::string_view separators = "") {
  const auto blank = [separators](char c) {
    return c == ' ' || c == '\t' || c == '\v' || c == '\f' || c == '\r' || c == '\n' || separators.find(c) != std::string_view::npos;
  };
  std::vector<TextWord> words;
  std::size_t i = 0;
  while (i < line.size()) {
    if (blank(line[i])) {
      ++i;
      continue;
    }
    const std::size_t start = i;
    while (i < line.size() && !blank(line[i])) ++i;
    words.push_back({line.substr(start, i - start), start + 1});
  }
  return words;
}

/// Drops a leading UTF-8 byte-order mark, which spreadsheets and Windows editors put before text
/// files; it carries nothing, and left in it made the first word unreadable ("'\xEF\xBB\xBFOFF'").
inline void strip_utf8_bom(std::string& text) {
  if (text.size() >= 3 && text.compare(0, 3, "\xEF\xBB\xBF") == 0) text.erase(0, 3);
}

/// Whether `text` is UTF-16: its byte-order mark (FF FE or FE FF), or, without one, the NUL byte UTF-16
/// puts beside each ASCII character, on the same side of the first four.
inline bool is_utf16(std::string_view text) {
  if (text.starts_with("\xFF\xFE") || text.starts_with("\xFE\xFF")) return true;
  if (text.size() < 8) return false;
  const bool low_first = text[0] != '\0' && text[1] == '\0';  // little-endian: 'A' 00
  for (std::size_t i = 0; i < 8; i += 2) {
    const char ascii = low_first ? text[i] : text[i + 1], nul = low_first ? text[i + 1] : text[i];
    if (ascii == '\0' || nul != '\0') return false;
  }
  return true;
}

/// Why `text` (from `name`) is not UTF-8 text, or nothing. Windows editors save "Unicode" text as
/// UTF-16, which parsers read as a NUL after every character and reported as mojibake; a NUL byte
/// elsewhere is no text either.
inline std::optional<std::string> utf8_text_problem(std::string_view text, const std::string& name) {
  if (is_utf16(text)) return name + ": is UTF-16, not UTF-8 text; save it as UTF-8";
  if (const std::size_t nul = text.find('\0'); nul != std::string_view::npos) {
    const TextPlace place = text_place(text, nul);
    return name + ":" + std::to_string(place.line) + ":" + std::to_string(place.column) + ": a NUL byte, which UTF-8 text never holds";
  }
  return std::nullopt;
}

/// A text input (procedure, poses, actions, preset, calibration, CSV, landmarks) read whole and
/// checked to be UTF-8 (utf8_text_problem), its byte-order mark dropped (strip_utf8_bom).
inline Result<std::string> read_utf8_text_file(const std::filesystem::path& path, const std::string& what = "") {
  Result<std::string> text = read_text_file(path, what);
  if (!text) return text;
  if (auto problem = utf8_text_problem(*text, path.string())) return Error{*problem};
  strip_utf8_bom(*text);
  return text;
}

}  // namespace resecto
