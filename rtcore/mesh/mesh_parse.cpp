// Strict, bounded readers for the four surface formats. Sections: text lines and words (shared),
// the face list every format fills, OFF, OBJ, PLY (ASCII and both binary byte orders), STL (ASCII
// and binary). Each reader checks a declared count against the bytes left before reserving memory.
#include "rtcore/mesh/mesh_parse.h"

#include <array>
#include <bit>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "rtcore/base/checked_number.h"
#include "rtcore/base/quoted_word.h"
#include "rtcore/base/text_file.h"

namespace resecto {
namespace {

// ---- Text lines and words: every error says file:line:column ----

/// Walks a text file line by line; words are runs between spaces and tabs.
class TextLines {
 public:
  TextLines(std::string_view text, const std::string& name) : text_(text), name_(name) {}

  /// The next line without its end of line; false at the end of the text. A line ends at "\n",
  /// "\r\n" or a lone "\r" (classic Mac OS exporters still write those).
  bool next(std::string_view& line) {
    if (offset_ >= text_.size()) return false;
    const std::size_t end = text_.find_first_of("\r\n", offset_);
    const std::size_t stop = end == std::string_view::npos ? text_.size() : end;
    line = text_.substr(offset_, stop - offset_);
    line_start_ = offset_;
    const bool crlf = end != std::string_view::npos && text_[end] == '\r' && end + 1 < text_.size() && text_[end + 1] == '\n';
    offset_ = end == std::string_view::npos ? text_.size() : end + (crlf ? 2 : 1);
    ++number_;
    return true;
  }
  /// The next OBJ statement: a line, joined with the lines after it while it ends in a backslash
  /// (the format's continuation), the backslashes dropped. A joined statement lives in `joined`.
  bool next_statement(std::string_view& statement, std::string& joined) {
    if (!next(statement)) return false;
    if (!continues(statement)) return true;
    joined.clear();
    std::string_view line = statement;
    while (continues(line)) {
      joined.append(line.substr(0, line.find_last_of('\\'))).push_back(' ');
      if (!next(line)) line = {};  // a backslash on the last line continues into nothing
    }
    joined.append(line);
    statement = joined;
    return true;
  }
  std::size_t bytes_left() const { return text_.size() - offset_; }
  std::size_t offset() const { return offset_; }
  int number() const { return number_; }
  /// "name:line:column: what" for a word inside the current line ("name:line: what" for a word of a
  /// statement joined over several lines, whose columns are not the file's).
  Error error_at(std::string_view word, const std::string& what) const {
    const std::less<const char*> before;
    if (before(word.data(), text_.data() + line_start_) || before(text_.data() + offset_, word.data())) return error(what);
    const std::size_t column = static_cast<std::size_t>(word.data() - text_.data()) - line_start_ + 1;
    return Error{name_ + ":" + std::to_string(number_) + ":" + std::to_string(column) + ": " + what};
  }
  Error error(const std::string& what) const { return Error{name_ + ":" + std::to_string(number_) + ": " + what}; }

 private:
  /// Whether a line ends in a backslash, after any spaces (and is not a comment).
  static bool continues(std::string_view line) {
    const std::size_t last = line.find_last_not_of(" \t\r\f\v");
    return last != std::string_view::npos && line[last] == '\\' && line.find('#') == std::string_view::npos;
  }

  std::string_view text_;
  const std::string& name_;
  std::size_t offset_ = 0;
  std::size_t line_start_ = 0;
  int number_ = 0;
};

/// The words of one line, '#' starting a comment when the format has them.
std::vector<std::string_view> split_words(std::string_view line, bool hash_comments) {
  if (hash_comments) {
    if (const std::size_t hash = line.find('#'); hash != std::string_view::npos) line = line.substr(0, hash);
  }
  std::vector<std::string_view> words;
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t' || line[i] == '\r' || line[i] == '\f' || line[i] == '\v')) ++i;
    const std::size_t start = i;
    while (i < line.size() && !(line[i] == ' ' || line[i] == '\t' || line[i] == '\r' || line[i] == '\f' || line[i] == '\v')) ++i;
    if (i > start) words.push_back(line.substr(start, i - start));
  }
  return words;
}

/// A whole word as an integer; nullopt when it is not one (or does not fit 64 bits).
std::optional<std::int64_t> parse_integer(std::string_view word) {
  std::int64_t value = 0;
  if (!word.empty() && word.front() == '+') word.remove_prefix(1);
  const auto [end, error] = std::from_chars(word.data(), word.data() + word.size(), value);
  if (word.empty() || error != std::errc{} || end != word.data() + word.size()) return std::nullopt;
  return value;
}

Result<double> coordinate(const TextLines& lines, std::string_view word) {
  const std::optional<double> value = parse_finite(word);
  if (!value) return lines.error_at(word, quoted_word(word) + " is " + not_finite_kind(word));
  return *value;
}

/// A little-endian 32-bit word at `at` (STL's byte order), on any host.
std::uint32_t little_endian_u32(std::string_view bytes, std::size_t at) {
  const auto* b = reinterpret_cast<const unsigned char*>(bytes.data() + at);
  return std::uint32_t{b[0]} | std::uint32_t{b[1]} << 8 | std::uint32_t{b[2]} << 16 | std::uint32_t{b[3]} << 24;
}

/// A whole word as any number, NaN included (for values that are read and dropped).
bool is_number(std::string_view word) {
  double value = 0.0;
  if (!word.empty() && word.front() == '+') word.remove_prefix(1);
  const auto [end, error] = std::from_chars(word.data(), word.data() + word.size(), value);
  return !word.empty() && error == std::errc{} && end == word.data() + word.size();
}

// ---- The face list every reader fills ----

/// Vertices and polygons as read, before the fan triangulation.
struct RawMesh {
  std::vector<Vec3> points;
  std::vector<std::uint32_t> corners;       // every polygon's corners, one after another
  std::vector<std::uint32_t> corner_start;  // polygon p is corners[corner_start[p], corner_start[p + 1])
  RawMesh() { corner_start.push_back(0); }
  std::size_t face_count() const { return corner_start.size() - 1; }
  void end_face() { corner_start.push_back(static_cast<std::uint32_t>(corners.size())); }
};

Result<TriangleMesh> triangulate(const RawMesh& raw, const std::string& name, double metres_per_unit) {
  if (raw.face_count() == 0) return Error{name + ": the file holds no faces"};
  // Every reader's points pass here, so the bound is checked once for all formats, in the file's
  // own millimetres whatever scale the caller reads them at.
  if (Status sane = check_coordinate_bound(raw.points, 1.0); !sane) return Error{name + ": " + sane.error()};
  TriangleMesh mesh;
  mesh.positions.reserve(raw.points.size());
  for (const Vec3& p : raw.points) mesh.positions.push_back(p * metres_per_unit);
  // Faces keep file order; a polygon becomes a fan around its first corner, also in file order.
  for (std::size_t f = 0; f < raw.face_count(); ++f) {
    const std::uint32_t first = raw.corner_start[f];
    const std::uint32_t end = raw.corner_start[f + 1];
    for (std::uint32_t c = first; c < end; ++c) {
      if (raw.corners[c] >= raw.points.size()) {
        return Error{name + ": face " + std::to_string(f) + " refers to vertex " + std::to_string(raw.corners[c]) +
                     ", but the file has " + std::to_string(raw.points.size()) + " vertices"};
      }
    }
    for (std::uint32_t c = first + 1; c + 1 < end; ++c) {
      mesh.triangles.push_back({raw.corners[first], raw.corners[c], raw.corners[c + 1]});
      mesh.file_faces.push_back(static_cast<std::uint32_t>(f));
    }
  }
  if (mesh.triangles.size() == raw.face_count()) mesh.file_faces.clear();  // triangles only: face t is triangle t
  return mesh;
}

/// A declared count checked before anything is reserved: within the cap and within what the bytes
/// left could hold at `min_bytes_each`.
std::optional<std::string> count_problem(std::int64_t count, std::size_t cap, std::size_t bytes_left, std::size_t min_bytes_each,
                                         const char* what) {
  if (count < 0) return std::string(what) + " count " + std::to_string(count) + " is negative";
  if (static_cast<std::uint64_t>(count) > cap) {
    return std::string(what) + " count " + std::to_string(count) + " is over the limit of " + std::to_string(cap);
  }
  if (min_bytes_each > 0 && static_cast<std::uint64_t>(count) > bytes_left / min_bytes_each) {
    return std::string(what) + " count " + std::to_string(count) + " needs at least " + std::to_string(min_bytes_each) + " bytes each, but only " +
           std::to_string(bytes_left) + " bytes follow (truncated file or a wrong count)";
  }
  return std::nullopt;
}

// ---- OFF (plain ASCII) ----

Result<RawMesh> parse_off(std::string_view text, const std::string& name) {
  TextLines lines(text, name);
  std::string_view line;
  std::vector<std::string_view> header;  // "OFF" and the three counts, over one or two lines
  while (header.size() < 4 && lines.next(line)) {
    const std::size_t header_before = header.size();
    for (std::string_view word : split_words(line, true)) {
      if (header.empty()) {
        if (word == "OFF") {
          header.push_back(word);
          continue;
        }
        if (word.size() > 3 && word.substr(word.size() - 3) == "OFF") {
          return lines.error_at(word, "'" + std::string(word) + "' files are not read; only plain 'OFF' (no colours, normals or 4D)");
        }
        return lines.error_at(word, "expected 'OFF' at the start of the file, found " + quoted_word(word));
      }
      if (word == "BINARY") return lines.error_at(word, "binary OFF is not read; write it as ASCII OFF");
      if (header.size() == 4) return lines.error_at(word, "unexpected " + quoted_word(word) + " after the vertex, face and edge counts");
      header.push_back(word);
    }
    // Some exporters write only the vertex and face counts on their line ("8 6"): the edge count,
    // which no reader uses, is then taken as 0 rather than read from the first vertex (audit 32, F14).
    if (header_before <= 1 && header.size() == 3) header.push_back("0");
  }
  if (header.empty()) return Error{name + ": expected 'OFF' at the start of the file, found nothing"};
  if (header.size() < 4) return lines.error("the header ends before its vertex, face and edge counts");
  std::int64_t counts[3];
  for (int i = 0; i < 3; ++i) {
    const std::optional<std::int64_t> count = parse_integer(header[static_cast<std::size_t>(i) + 1]);
    if (!count) return lines.error_at(header[static_cast<std::size_t>(i) + 1], quoted_word(header[static_cast<std::size_t>(i) + 1]) + " is not a count");
    counts[i] = *count;
  }
  // The shortest vertex line is "0 0 0\n" (6 bytes), the shortest face line "3 0 1 2\n" (8).
  if (auto problem = count_problem(counts[0], kMaxMeshVertices, lines.bytes_left(), 6, "vertex")) return lines.error_at(header[1], *problem);
  if (auto problem = count_problem(counts[1], kMaxMeshFaces, lines.bytes_left(), 8, "face")) return lines.error_at(header[2], *problem);
  if (counts[2] < 0) return lines.error_at(header[3], "edge count " + std::to_string(counts[2]) + " is negative");
  const auto vertex_count = static_cast<std::size_t>(counts[0]);
  const auto face_count = static_cast<std::size_t>(counts[1]);
  RawMesh raw;
  raw.points.reserve(vertex_count);
  raw.corner_start.reserve(face_count + 1);
  raw.corners.reserve(3 * face_count);
  while (raw.points.size() < vertex_count || raw.face_count() < face_count) {
    if (!lines.next(line)) {
      return Error{name + ": the file ends after " + std::to_string(raw.points.size()) + " of " + std::to_string(vertex_count) +
                   " vertices and " + std::to_string(raw.face_count()) + " of " + std::to_string(face_count) + " faces (truncated?)"};
    }
    const std::vector<std::string_view> words = split_words(line, true);
    if (words.empty()) continue;
    if (raw.points.size() < vertex_count) {
      if (words.size() != 3) return lines.error("vertex " + std::to_string(raw.points.size()) + ": expected 3 coordinates, found " + std::to_string(words.size()));
      double xyz[3];
      for (int i = 0; i < 3; ++i) {
        Result<double> value = coordinate(lines, words[static_cast<std::size_t>(i)]);
        if (!value) return Error{value.error()};
        xyz[i] = *value;
      }
      raw.points.push_back(Vec3(xyz[0], xyz[1], xyz[2]));
      continue;
    }
    const std::optional<std::int64_t> corners = parse_integer(words[0]);
    if (!corners) return lines.error_at(words[0], "face " + std::to_string(raw.face_count()) + ": " + quoted_word(words[0]) + " is not a corner count");
    if (*corners < 3 || *corners > static_cast<std::int64_t>(kMaxPolygonCorners)) {
      return lines.error_at(words[0], "face " + std::to_string(raw.face_count()) + " has " + std::to_string(*corners) +
                                          " corners (3 to " + std::to_string(kMaxPolygonCorners) + " are read)");
    }
    // After the corners an OFF face line may carry a colour: 3 or 4 numbers, ignored.
    const auto n = static_cast<std::size_t>(*corners);
    const std::size_t extra = words.size() - 1 < n ? 0 : words.size() - 1 - n;
    if (words.size() - 1 < n || !(extra == 0 || extra == 3 || extra == 4)) {
      return lines.error("face " + std::to_string(raw.face_count()) + ": expected " + std::to_string(n) + " vertex indices (and at most a colour), found " +
                         std::to_string(words.size() - 1) + " numbers");
    }
    for (std::size_t c = 1; c <= n; ++c) {
      const std::optional<std::int64_t> index = parse_integer(words[c]);
      if (!index) return lines.error_at(words[c], "face " + std::to_string(raw.face_count()) + ": vertex index " + quoted_word(words[c]) + " is not a whole number");
      if (*index < 0 || static_cast<std::uint64_t>(*index) >= vertex_count) {
        return lines.error_at(words[c], "face " + std::to_string(raw.face_count()) + ": vertex index " + quoted_word(words[c]) +
                                            " is not in [0, " + std::to_string(vertex_count) + ")");
      }
      raw.corners.push_back(static_cast<std::uint32_t>(*index));
    }
    for (std::size_t c = n + 1; c < words.size(); ++c) {
      if (!is_number(words[c])) return lines.error_at(words[c], "face colour " + quoted_word(words[c]) + " is not a number");
    }
    raw.end_face();
  }
  while (lines.next(line)) {
    const std::vector<std::string_view> words = split_words(line, true);
    if (!words.empty()) return lines.error_at(words[0], "more data after the " + std::to_string(face_count) + " faces the header declares");
  }
  return raw;
}

// ---- OBJ ----

/// What follows a face corner's vertex index: nothing, "/vt", "//vn" or "/vt/vn", each an integer.
/// The texture and normal indices are not used, but a corner such as "1/x/3" is no corner at all.
bool texture_and_normal_indices_well_formed(std::string_view rest) {
  if (rest.empty()) return true;
  if (rest.front() != '/') return false;
  rest.remove_prefix(1);
  const std::size_t slash = rest.find('/');
  const std::string_view texture = rest.substr(0, slash);
  if (slash == std::string_view::npos) return parse_integer(texture).has_value();  // v/vt
  const std::string_view normal = rest.substr(slash + 1);
  return (texture.empty() || parse_integer(texture).has_value()) && parse_integer(normal).has_value();
}

Result<RawMesh> parse_obj(std::string_view text, const std::string& name) {
  // Statements a surface does not need; anything else unknown is an error, not silently skipped.
  static constexpr std::string_view kIgnored[] = {"vt", "vn", "vp", "g", "o", "s", "usemtl", "mtllib", "l", "p", "lod", "shadow_obj", "trace_obj", "mg"};
  TextLines lines(text, name);
  RawMesh raw;
  std::vector<int> face_lines;  // each face's line, for an index that turns out out of range
  std::string_view line;
  std::string joined;  // a statement continued over several lines
  while (lines.next_statement(line, joined)) {
    const std::vector<std::string_view> words = split_words(line, true);
    if (words.empty()) continue;
    const std::string_view keyword = words[0];
    if (keyword == "v") {
      // x y z, then w, or r g b (some writers put both): five numbers is none of these.
      if (words.size() < 4 || words.size() > 8 || words.size() == 6) {
        return lines.error("a vertex needs x y z (optionally w, or r g b), found " + std::to_string(words.size() - 1) + " numbers");
      }
      if (raw.points.size() == kMaxMeshVertices) return lines.error("more than " + std::to_string(kMaxMeshVertices) + " vertices");
      double xyz[3];
      for (std::size_t i = 1; i < words.size(); ++i) {
        Result<double> value = coordinate(lines, words[i]);
        if (!value) return Error{value.error()};
        if (i <= 3) xyz[i - 1] = *value;
      }
      raw.points.push_back(Vec3(xyz[0], xyz[1], xyz[2]));
    } else if (keyword == "f") {
      if (words.size() < 4) return lines.error("a face needs at least 3 corners, found " + std::to_string(words.size() - 1));
      if (words.size() - 1 > kMaxPolygonCorners) return lines.error("a face with more than " + std::to_string(kMaxPolygonCorners) + " corners");
      if (raw.face_count() == kMaxMeshFaces) return lines.error("more than " + std::to_string(kMaxMeshFaces) + " faces");
      for (std::size_t c = 1; c < words.size(); ++c) {
        const std::string_view corner = words[c].substr(0, words[c].find('/'));  // "v", "v/vt", "v//vn", "v/vt/vn"
        const std::optional<std::int64_t> index = parse_integer(corner);
        if (!index || !texture_and_normal_indices_well_formed(words[c].substr(corner.size()))) {
          return lines.error_at(words[c], "corner " + quoted_word(words[c]) + " is not a vertex index (v, v/vt, v//vn or v/vt/vn)");
        }
        // OBJ counts from 1; a negative index counts back from the latest vertex.
        const std::int64_t resolved = *index > 0 ? *index - 1 : static_cast<std::int64_t>(raw.points.size()) + *index;
        if (*index == 0 || resolved < 0 || resolved >= static_cast<std::int64_t>(kMaxMeshVertices)) {
          return lines.error_at(words[c], "vertex index " + quoted_word(corner) + " is not in [1, " + std::to_string(kMaxMeshVertices) +
                                              "] or a valid negative index (" + std::to_string(raw.points.size()) + " vertices so far)");
        }
        raw.corners.push_back(static_cast<std::uint32_t>(resolved));
      }
      raw.end_face();
      face_lines.push_back(lines.number());
    } else {
      bool ignored = false;
      for (std::string_view known : kIgnored) ignored = ignored || keyword == known;
      if (!ignored) return lines.error_at(keyword, "unknown statement " + quoted_word(keyword));
    }
  }
  for (std::size_t f = 0; f < raw.face_count(); ++f) {
    for (std::uint32_t c = raw.corner_start[f]; c < raw.corner_start[f + 1]; ++c) {
      if (raw.corners[c] >= raw.points.size()) {
        return Error{name + ":" + std::to_string(face_lines[f]) + ": face " + std::to_string(f) + " refers to vertex " +
                     std::to_string(raw.corners[c] + 1) + ", but the file has " + std::to_string(raw.points.size()) + " vertices"};
      }
    }
  }
  return raw;
}

// ---- PLY ----

enum class PlyType { int8, uint8, int16, uint16, int32, uint32, float32, float64 };

std::optional<PlyType> ply_type(std::string_view word) {
  if (word == "char" || word == "int8") return PlyType::int8;
  if (word == "uchar" || word == "uint8") return PlyType::uint8;
  if (word == "short" || word == "int16") return PlyType::int16;
  if (word == "ushort" || word == "uint16") return PlyType::uint16;
  if (word == "int" || word == "int32") return PlyType::int32;
  if (word == "uint" || word == "uint32") return PlyType::uint32;
  if (word == "float" || word == "float32") return PlyType::float32;
  if (word == "double" || word == "float64") return PlyType::float64;
  return std::nullopt;
}

std::size_t ply_size(PlyType type) {
  constexpr std::size_t kSizes[] = {1, 1, 2, 2, 4, 4, 4, 8};
  return kSizes[static_cast<int>(type)];
}

bool ply_integral(PlyType type) { return type != PlyType::float32 && type != PlyType::float64; }

struct PlyProperty {
  std::string_view name;
  PlyType type = PlyType::float32;
  bool is_list = false;
  PlyType count_type = PlyType::uint8;
  int line = 0;  // of the header, for naming a property declared twice
};

struct PlyElement {
  std::string_view name;
  std::int64_t count = 0;
  std::vector<PlyProperty> properties;
};

/// Reads PLY values from the body: words for ASCII, fixed-size little- or big-endian for binary.
class PlyBody {
 public:
  PlyBody(std::string_view body, std::size_t body_offset, int format, const std::string& name)
      : body_(body), body_offset_(body_offset), format_(format), name_(name) {}

  std::size_t bytes_left() const { return body_.size() - offset_; }
  bool ascii() const { return format_ == 0; }

  Result<double> read(PlyType type, const char* what) {
    if (ascii()) {
      while (offset_ < body_.size() && is_space(body_[offset_])) ++offset_;
      const std::size_t start = offset_;
      while (offset_ < body_.size() && !is_space(body_[offset_])) ++offset_;
      if (start == offset_) return Error{name_ + ": the file ends inside " + what + " (truncated?)"};
      const std::string_view word = body_.substr(start, offset_ - start);
      const std::optional<double> value = ply_integral(type) ? to_double(parse_integer(word)) : parse_finite(word);
      if (!value) {
        return Error{name_ + ": byte " + std::to_string(body_offset_ + start) + ": " + what + " " + quoted_word(word) + " is " +
                     (ply_integral(type) ? "not a whole number" : not_finite_kind(word))};
      }
      return *value;
    }
    const std::size_t size = ply_size(type);
    if (bytes_left() < size) return Error{name_ + ": the file ends inside " + what + " (truncated?)"};
    unsigned char bytes[8];
    std::memcpy(bytes, body_.data() + offset_, size);
    const bool swap = (format_ == 1) != (std::endian::native == std::endian::little);
    if (swap) {
      for (std::size_t i = 0; i < size / 2; ++i) std::swap(bytes[i], bytes[size - 1 - i]);
    }
    offset_ += size;
    switch (type) {
      case PlyType::int8: return static_cast<double>(std::bit_cast<std::int8_t>(bytes[0]));
      case PlyType::uint8: return static_cast<double>(bytes[0]);
      case PlyType::int16: { std::int16_t v; std::memcpy(&v, bytes, 2); return static_cast<double>(v); }
      case PlyType::uint16: { std::uint16_t v; std::memcpy(&v, bytes, 2); return static_cast<double>(v); }
      case PlyType::int32: { std::int32_t v; std::memcpy(&v, bytes, 4); return static_cast<double>(v); }
      case PlyType::uint32: { std::uint32_t v; std::memcpy(&v, bytes, 4); return static_cast<double>(v); }
      case PlyType::float32: { float v; std::memcpy(&v, bytes, 4); return static_cast<double>(v); }
      case PlyType::float64: { double v; std::memcpy(&v, bytes, 8); return v; }
    }
    return 0.0;
  }

  /// ASCII: a row is one line, so after its last property only spaces may stand before the line's
  /// end. Read as one stream of words, a row with a value too many shifted every later one, and
  /// the error named some later face instead of this row.
  Status expect_row_end(const std::string& row, std::size_t properties) {
    if (!ascii()) return Ok{};
    while (offset_ < body_.size() && (body_[offset_] == ' ' || body_[offset_] == '\t')) ++offset_;
    if (offset_ >= body_.size() || body_[offset_] == '\n' || body_[offset_] == '\r') return Ok{};  // "\n", "\r\n" or a lone "\r"
    std::size_t end = offset_;
    while (end < body_.size() && !is_space(body_[end])) ++end;
    return Error{name_ + ": byte " + std::to_string(body_offset_ + offset_) + ": " + row + " has a value past its " + std::to_string(properties) +
                 (properties == 1 ? " property: " : " properties: ") + quoted_word(body_.substr(offset_, end - offset_)) + " (an ASCII row is one line)"};
  }

  /// Nothing but whitespace (ASCII) or nothing at all (binary) may follow the last element.
  Status expect_end() {
    if (ascii()) {
      while (offset_ < body_.size() && is_space(body_[offset_])) ++offset_;
    }
    if (offset_ != body_.size()) {
      return Error{name_ + ": byte " + std::to_string(body_offset_ + offset_) + ": " + std::to_string(bytes_left()) +
                   " bytes after the last element the header declares"};
    }
    return Ok{};
  }
  std::size_t position() const { return body_offset_ + offset_; }

 private:
  static bool is_space(char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\f' || c == '\v'; }
  static std::optional<double> to_double(std::optional<std::int64_t> v) {
    if (!v || *v < -(std::int64_t{1} << 53) || *v > (std::int64_t{1} << 53)) return std::nullopt;
    return static_cast<double>(*v);
  }

  std::string_view body_;
  std::size_t body_offset_;
  std::size_t offset_ = 0;
  int format_;  // 0 ascii, 1 binary little-endian, 2 binary big-endian
  const std::string& name_;
};

Result<RawMesh> parse_ply(std::string_view text, const std::string& name) {
  TextLines lines(text, name);
  std::string_view line;
  if (!lines.next(line) || line != "ply") return Error{name + ":1: expected 'ply' on the first line"};
  int format = -1;
  std::vector<PlyElement> elements;
  bool ended = false;
  while (!ended && lines.next(line)) {
    const std::vector<std::string_view> words = split_words(line, false);
    if (words.empty()) continue;
    const std::string_view keyword = words[0];
    if (keyword == "comment" || keyword == "obj_info") continue;
    if (keyword == "end_header") {
      ended = true;
    } else if (keyword == "format") {
      if (words.size() != 3 || words[2] != "1.0") return lines.error("expected 'format <ascii|binary_little_endian|binary_big_endian> 1.0'");
      if (words[1] == "ascii") format = 0;
      else if (words[1] == "binary_little_endian") format = 1;
      else if (words[1] == "binary_big_endian") format = 2;
      else return lines.error_at(words[1], "unknown PLY format " + quoted_word(words[1]));
    } else if (keyword == "element") {
      if (words.size() != 3) return lines.error("expected 'element <name> <count>'");
      const std::optional<std::int64_t> count = parse_integer(words[2]);
      if (!count || *count < 0) return lines.error_at(words[2], "element count " + quoted_word(words[2]) + " is not a count");
      if (elements.size() == 64) return lines.error("more than 64 elements");
      elements.push_back({words[1], *count, {}});
    } else if (keyword == "property") {
      if (elements.empty()) return lines.error("a property before any element");
      if (elements.back().properties.size() == 256) return lines.error("more than 256 properties in one element");
      PlyProperty property;
      if (words.size() == 5 && words[1] == "list") {
        const std::optional<PlyType> count_type = ply_type(words[2]);
        const std::optional<PlyType> item_type = ply_type(words[3]);
        if (!count_type || !ply_integral(*count_type)) return lines.error_at(words[2], "a list's count type must be an integer type, not " + quoted_word(words[2]));
        if (!item_type) return lines.error_at(words[3], "unknown PLY type " + quoted_word(words[3]));
        property = {words[4], *item_type, true, *count_type};
      } else if (words.size() == 3) {
        const std::optional<PlyType> type = ply_type(words[1]);
        if (!type) return lines.error_at(words[1], "unknown PLY type " + quoted_word(words[1]));
        property = {words[2], *type, false, PlyType::uint8};
      } else {
        return lines.error("expected 'property <type> <name>' or 'property list <count type> <item type> <name>'");
      }
      // Two columns of one name: which one the reader took was arbitrary (the later one, silently), and a
      // wrong one showed only as some face's degenerate triangle far from the header line at fault.
      for (const PlyProperty& earlier : elements.back().properties) {
        if (earlier.name == property.name) {
          return lines.error_at(property.name, "element '" + std::string(elements.back().name) + "' declares property " +
                                                   quoted_word(property.name) + " twice (first on line " + std::to_string(earlier.line) +
                                                   ")");
        }
      }
      property.line = lines.number();
      elements.back().properties.push_back(property);
    } else {
      return lines.error_at(keyword, "unknown header line " + quoted_word(keyword));
    }
  }
  if (!ended) return Error{name + ": the header has no 'end_header' line"};
  if (format < 0) return Error{name + ": the header has no 'format' line"};

  // Where x, y, z and the face corners live; every other property is read and dropped.
  int vertex_element = -1, face_element = -1;
  int axis[3] = {-1, -1, -1};
  int corners_property = -1;
  for (std::size_t e = 0; e < elements.size(); ++e) {
    const PlyElement& element = elements[e];
    if (element.name == "vertex" && vertex_element < 0) {
      vertex_element = static_cast<int>(e);
      for (std::size_t p = 0; p < element.properties.size(); ++p) {
        for (int a = 0; a < 3; ++a) {
          static constexpr std::string_view kAxes[] = {"x", "y", "z"};
          if (element.properties[p].name == kAxes[a] && !element.properties[p].is_list) axis[a] = static_cast<int>(p);
        }
      }
    } else if (element.name == "face" && face_element < 0) {
      face_element = static_cast<int>(e);
      for (std::size_t p = 0; p < element.properties.size(); ++p) {
        const PlyProperty& property = element.properties[p];
        if (property.is_list && (property.name == "vertex_indices" || property.name == "vertex_index")) {
          if (!ply_integral(property.type)) return Error{name + ": face vertex indices must have an integer type"};
          corners_property = static_cast<int>(p);
        }
      }
    }
  }
  if (vertex_element < 0 || axis[0] < 0 || axis[1] < 0 || axis[2] < 0) return Error{name + ": no 'vertex' element with x, y and z properties"};
  if (face_element < 0 || corners_property < 0) return Error{name + ": no 'face' element with a 'vertex_indices' list"};

  PlyBody body(text.substr(lines.offset()), lines.offset(), format, name);
  RawMesh raw;
  for (std::size_t e = 0; e < elements.size(); ++e) {
    const PlyElement& element = elements[e];
    // The least one row can take: binary, its scalars and list counts; ASCII, a digit and a space each.
    std::size_t min_row = 0;
    for (const PlyProperty& property : element.properties) min_row += body.ascii() ? 2 : ply_size(property.is_list ? property.count_type : property.type);
    const std::size_t cap = static_cast<int>(e) == vertex_element ? kMaxMeshVertices : kMaxMeshFaces;
    if (auto problem = count_problem(element.count, cap, body.bytes_left(), min_row, "element")) {
      return Error{name + ": element '" + std::string(element.name) + "': " + *problem};
    }
    const bool is_vertex = static_cast<int>(e) == vertex_element;
    const bool is_face = static_cast<int>(e) == face_element;
    if (is_vertex) raw.points.reserve(static_cast<std::size_t>(element.count));
    if (is_face) raw.corner_start.reserve(static_cast<std::size_t>(element.count) + 1);
    for (std::int64_t row = 0; row < element.count; ++row) {
      double xyz[3] = {0.0, 0.0, 0.0};
      for (std::size_t p = 0; p < element.properties.size(); ++p) {
        const PlyProperty& property = element.properties[p];
        const std::string what = std::string(element.name) + " " + std::to_string(row) + " " + std::string(property.name);
        if (!property.is_list) {
          const std::size_t at = body.position();
          Result<double> value = body.read(property.type, what.c_str());
          if (!value) return Error{value.error()};
          for (int a = 0; a < 3; ++a) {
            if (is_vertex && static_cast<int>(p) == axis[a]) {
              if (!std::isfinite(*value)) return Error{name + ": byte " + std::to_string(at) + ": " + what + " is not finite"};
              xyz[a] = *value;
            }
          }
          continue;
        }
        Result<double> length = body.read(property.count_type, what.c_str());
        if (!length) return Error{length.error()};
        const bool corners = is_face && static_cast<int>(p) == corners_property;
        const std::size_t item_min = body.ascii() ? 2 : ply_size(property.type);
        if (corners && (*length < 3 || *length > static_cast<double>(kMaxPolygonCorners))) {
          return Error{name + ": byte " + std::to_string(body.position()) + ": " + what + " has " + exact_number(*length) + " corners (3 to " +
                       std::to_string(kMaxPolygonCorners) + " are read)"};
        }
        if (*length < 0) return Error{name + ": byte " + std::to_string(body.position()) + ": " + what + " has a negative count " + exact_number(*length)};
        if (*length > static_cast<double>(body.bytes_left() / item_min)) {
          return Error{name + ": byte " + std::to_string(body.position()) + ": " + what + " has " + exact_number(*length) + " items, but " +
                       std::to_string(body.bytes_left()) + " bytes are left: the file is cut short"};
        }
        for (std::int64_t i = 0; i < static_cast<std::int64_t>(*length); ++i) {
          Result<double> item = body.read(property.type, what.c_str());
          if (!item) return Error{item.error()};
          if (!corners) continue;
          if (*item < 0 || *item >= static_cast<double>(kMaxMeshVertices)) {
            return Error{name + ": " + what + ": vertex index " + exact_number(*item) + " is out of range"};
          }
          raw.corners.push_back(static_cast<std::uint32_t>(*item));
        }
        if (corners) raw.end_face();
      }
      if (Status row_end = body.expect_row_end(std::string(element.name) + " " + std::to_string(row), element.properties.size()); !row_end) {
        return Error{row_end.error()};
      }
      if (is_vertex) raw.points.push_back(Vec3(xyz[0], xyz[1], xyz[2]));
    }
  }
  if (Status end = body.expect_end(); !end) return Error{end.error()};
  return raw;
}

// ---- STL ----

/// STL repeats a corner in every triangle that shares it; identical coordinates become one vertex
/// (-0 and +0 compare equal), numbered in order of first appearance.
class CornerMerger {
 public:
  std::uint32_t add(RawMesh& raw, const Vec3& p) {
    const auto [it, inserted] = index_.try_emplace({p.x, p.y, p.z}, static_cast<std::uint32_t>(raw.points.size()));
    if (inserted) raw.points.push_back(p);
    return it->second;
  }

 private:
  std::map<std::array<double, 3>, std::uint32_t> index_;
};

Result<RawMesh> parse_binary_stl(std::string_view bytes, const std::string& name) {
  const std::uint32_t declared = little_endian_u32(bytes, 80);
  const std::uint64_t expected = 84 + 50 * std::uint64_t{declared};
  if (expected != bytes.size()) {
    return Error{name + ": binary STL declares " + std::to_string(declared) + " triangles (" + std::to_string(expected) +
                 " bytes), but the file is " + std::to_string(bytes.size()) + " bytes (truncated, or not an STL file)"};
  }
  if (declared > kMaxMeshFaces) return Error{name + ": binary STL declares " + std::to_string(declared) + " triangles, over the limit of " + std::to_string(kMaxMeshFaces)};
  RawMesh raw;
  CornerMerger merger;
  raw.corners.reserve(3 * std::size_t{declared});
  raw.corner_start.reserve(std::size_t{declared} + 1);
  for (std::uint32_t t = 0; t < declared; ++t) {
    const std::size_t base = 84 + 50 * std::size_t{t};
    for (int corner = 0; corner < 3; ++corner) {
      float xyz[3];
      for (int a = 0; a < 3; ++a) {
        const std::uint32_t bits = little_endian_u32(bytes, base + 12 + 12 * static_cast<std::size_t>(corner) + 4 * static_cast<std::size_t>(a));
        xyz[a] = std::bit_cast<float>(bits);
        if (!std::isfinite(xyz[a])) {
          return Error{name + ": byte " + std::to_string(base + 12 + 12 * static_cast<std::size_t>(corner)) + ": triangle " + std::to_string(t) +
                       " corner " + std::to_string(corner) + " is not finite"};
        }
      }
      raw.corners.push_back(merger.add(raw, Vec3(xyz[0], xyz[1], xyz[2])));
    }
    raw.end_face();
  }
  return raw;
}

// ASCII STL's keywords in any case: older CAD exporters write them in capitals ("SOLID", "FACET
// NORMAL", "VERTEX"), which read as a binary file claiming 774910240 triangles (audit 25, F4).
bool stl_keyword(std::string_view word, std::string_view lower) {
  return word.size() == lower.size() &&
         std::equal(word.begin(), word.end(), lower.begin(), [](char a, char b) { return std::tolower(static_cast<unsigned char>(a)) == b; });
}

Result<RawMesh> parse_ascii_stl(std::string_view text, const std::string& name) {
  TextLines lines(text, name);
  RawMesh raw;
  CornerMerger merger;
  // The grammar as a state machine over lines: solid, then facets, then endsolid (repeatable).
  enum class Expect { solid, facet_or_end, outer_loop, vertex, endloop, endfacet, nothing } expect = Expect::solid;
  int corner = 0;
  std::string_view line;
  while (lines.next(line)) {
    const std::vector<std::string_view> words = split_words(line, false);
    if (words.empty()) continue;
    const std::string_view keyword = words[0];
    auto expected = [&](const char* what) { return lines.error_at(keyword, std::string("expected ") + what + ", found " + quoted_word(keyword)); };
    switch (expect) {
      case Expect::solid:
      case Expect::nothing:
        if (!stl_keyword(keyword, "solid")) return expected(expect == Expect::solid ? "'solid'" : "'solid' or the end of the file");
        expect = Expect::facet_or_end;
        break;
      case Expect::facet_or_end:
        if (stl_keyword(keyword, "endsolid")) {
          expect = Expect::nothing;
          break;
        }
        if (!stl_keyword(keyword, "facet")) return expected("'facet' or 'endsolid'");
        if (words.size() != 5 || !stl_keyword(words[1], "normal")) return lines.error("expected 'facet normal nx ny nz'");
        for (std::size_t i = 2; i < 5; ++i) {
          if (!is_number(words[i])) {
            return lines.error_at(words[i], "normal " + quoted_word(words[i]) + " is not a number");
          }
        }
        if (raw.face_count() == kMaxMeshFaces) return lines.error("more than " + std::to_string(kMaxMeshFaces) + " facets");
        expect = Expect::outer_loop;
        break;
      case Expect::outer_loop:
        if (words.size() != 2 || !stl_keyword(keyword, "outer") || !stl_keyword(words[1], "loop")) return expected("'outer loop'");
        expect = Expect::vertex;
        corner = 0;
        break;
      case Expect::vertex: {
        if (!stl_keyword(keyword, "vertex")) return expected("'vertex'");
        if (words.size() != 4) return lines.error("expected 'vertex x y z'");
        double xyz[3];
        for (int a = 0; a < 3; ++a) {
          Result<double> value = coordinate(lines, words[static_cast<std::size_t>(a) + 1]);
          if (!value) return Error{value.error()};
          xyz[a] = *value;
        }
        raw.corners.push_back(merger.add(raw, Vec3(xyz[0], xyz[1], xyz[2])));
        if (++corner == 3) expect = Expect::endloop;
        break;
      }
      case Expect::endloop:
        if (!stl_keyword(keyword, "endloop")) return expected("'endloop' (a facet has 3 vertices)");
        expect = Expect::endfacet;
        break;
      case Expect::endfacet:
        if (!stl_keyword(keyword, "endfacet")) return expected("'endfacet'");
        raw.end_face();
        expect = Expect::facet_or_end;
        break;
    }
  }
  if (expect != Expect::nothing) return Error{name + ": the file ends inside a solid (truncated? no 'endsolid')"};
  return raw;
}

Result<RawMesh> parse_stl(std::string_view bytes, const std::string& name) {
  // A binary STL's size is exactly 84 + 50 per triangle; its 80-byte header may itself start with
  // "solid", so the size decides first.
  if (bytes.size() >= 84) {
    const std::uint32_t declared = little_endian_u32(bytes, 80);
    if (84 + 50 * std::uint64_t{declared} == bytes.size()) return parse_binary_stl(bytes, name);
  }
  // Not a binary one's size: an ASCII STL saved as UTF-16 ("Unicode") would read as neither.
  if (is_utf16(bytes)) return Error{name + ": is UTF-16, not UTF-8 text; save it as UTF-8"};
  // An editor may put a UTF-8 byte-order mark before "solid" (the other formats' readers drop it
  // earlier; a binary STL's header may begin with those bytes, so here only ahead of the text).
  const std::string_view text = bytes.starts_with("\xEF\xBB\xBF") ? bytes.substr(3) : bytes;
  const std::size_t first = text.find_first_not_of(" \t\r\n");
  if (first != std::string_view::npos && stl_keyword(text.substr(first, 5), "solid")) return parse_ascii_stl(text, name);
  if (bytes.size() >= 84) return parse_binary_stl(bytes, name);
  return Error{name + ": neither ASCII STL (no 'solid') nor binary STL (" + std::to_string(bytes.size()) + " bytes, under the 84-byte header)"};
}

}  // namespace

Result<TriangleMesh> parse_surface_mesh(std::string_view bytes, MeshFormat format, const std::string& name, double metres_per_unit) {
  if (bytes.empty()) return Error{name + ": file is empty"};
  if (bytes.size() > kMaxMeshFileBytes) return Error{name + ": over the " + std::to_string(kMaxMeshFileBytes) + "-byte limit for a mesh"};
  Result<RawMesh> raw = Error{""};
  switch (format) {
    case MeshFormat::off: raw = parse_off(bytes, name); break;
    case MeshFormat::obj: raw = parse_obj(bytes, name); break;
    case MeshFormat::ply: raw = parse_ply(bytes, name); break;
    case MeshFormat::stl: raw = parse_stl(bytes, name); break;
  }
  if (!raw) return Error{raw.error()};
  return triangulate(*raw, name, metres_per_unit);
}

}  // namespace resecto
