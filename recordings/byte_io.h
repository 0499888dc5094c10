// Little-endian byte packing for the recording's payloads: a growing writer and a bounds-checked
// reader that never reads past its span (a damaged or hostile length field yields `ok() == false`,
// not a crash or a huge allocation).
#pragma once

#include <bit>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <span>
#include <string>
#include <vector>

namespace resecto::rec {

static_assert(std::endian::native == std::endian::little, "the recording format is little-endian; so is every supported host");

/// Appends fixed-width little-endian values.
class ByteWriter {
 public:
  explicit ByteWriter(std::vector<std::uint8_t>& out) : out_(out) {}
  template <class T>
  void put(T value) {
    static_assert(std::is_trivially_copyable_v<T>);
    put_raw(&value, sizeof(T));
  }
  void put_bytes(std::span<const std::uint8_t> bytes) { put_raw(bytes.data(), bytes.size()); }
  std::size_t size() const { return out_.size(); }

 private:
  // resize + memcpy rather than insert(): GCC 12 at -O3 sees false bounds overflows in the latter.
  void put_raw(const void* data, std::size_t n) {
    if (n == 0) return;
    const std::size_t at = out_.size();
    out_.resize(at + n);
    std::memcpy(out_.data() + at, data, n);
  }
  std::vector<std::uint8_t>& out_;
};

/// Reads fixed-width little-endian values; after any read past the end every later read yields
/// zeros and ok() stays false.
class ByteReader {
 public:
  explicit ByteReader(std::span<const std::uint8_t> bytes) : bytes_(bytes) {}
  template <class T>
  T get() {
    static_assert(std::is_trivially_copyable_v<T>);
    T value{};
    if (!ok_ || bytes_.size() - offset_ < sizeof(T)) {
      ok_ = false;
      return value;
    }
    std::memcpy(&value, bytes_.data() + offset_, sizeof(T));
    offset_ += sizeof(T);
    return value;
  }
  /// The next `n` bytes, or an empty span (and !ok()) when fewer remain.
  std::span<const std::uint8_t> get_bytes(std::size_t n) {
    if (!ok_ || bytes_.size() - offset_ < n) {
      ok_ = false;
      return {};
    }
    std::span<const std::uint8_t> out = bytes_.subspan(offset_, n);
    offset_ += n;
    return out;
  }
  std::size_t remaining() const { return ok_ ? bytes_.size() - offset_ : 0; }
  bool ok() const { return ok_; }

 private:
  std::span<const std::uint8_t> bytes_;
  std::size_t offset_ = 0;
  bool ok_ = true;
};

}  // namespace resecto::rec
