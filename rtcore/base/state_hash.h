// StateHasher: the 64-bit state hash the core records at every collision step (DESIGN.md "Data
// flow"), FNV-1a over 64-bit words of raw bytes in index order, so equal states hash equal. In base
// because the tissue hashes its own state with it and the core hashes the tissue's hash, the tick
// and the tool's poses (simulation.cpp).
#pragma once

#include <cstdint>
#include <cstring>
#include <span>
#include <string>

namespace resecto {

/// Word-wise FNV-1a: eight bytes per multiply, byte order as in memory.
class StateHasher {
 public:
  /// Adds the raw bytes of a span of trivially copyable values.
  template <class T>
  void add(std::span<const T> values) {
    add_bytes(values.data(), values.size_bytes());
  }
  void add_bytes(const void* data, std::size_t size);
  std::uint64_t value() const { return hash_; }

 private:
  std::uint64_t hash_ = 0xcbf29ce484222325ull;
};

/// A state hash as every output writes it: sixteen lower-case hex digits.
std::string hex_hash(std::uint64_t hash);

}  // namespace resecto
