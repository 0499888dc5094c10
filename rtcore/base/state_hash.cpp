// Word-wise FNV-1a: the tail shorter than a word is zero-padded, and the length is mixed in last so
// spans that differ only in trailing zero bytes still differ.
#include "rtcore/base/state_hash.h"

namespace resecto {

void StateHasher::add_bytes(const void* data, std::size_t size) {
  constexpr std::uint64_t kPrime = 0x100000001b3ull;
  const auto* bytes = static_cast<const unsigned char*>(data);
  std::size_t offset = 0;
  for (; offset + 8 <= size; offset += 8) {
    std::uint64_t word;
    std::memcpy(&word, bytes + offset, 8);
    hash_ = (hash_ ^ word) * kPrime;
  }
  if (offset < size) {
    std::uint64_t word = 0;
    std::memcpy(&word, bytes + offset, size - offset);
    hash_ = (hash_ ^ word) * kPrime;
  }
  hash_ = (hash_ ^ static_cast<std::uint64_t>(size)) * kPrime;
}

}  // namespace resecto
