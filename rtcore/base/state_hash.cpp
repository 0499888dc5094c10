// Word-wise FNV-1a in four lanes: a span's 32-byte blocks feed four independent lanes, which fold
// into the running hash; the remaining words, the zero-padded tail and the length follow as one
// lane. Each lane's multiply waits only on its own, so the multiply's latency no longer bounds a
// long span: the core hashes half a megabyte of positions and velocities at every collision tick.
// The length is mixed in last so spans that differ only in trailing zero bytes still differ.
#include "rtcore/base/state_hash.h"

#include <cstdio>

namespace resecto {

std::string hex_hash(std::uint64_t hash) {
  char text[17];
  std::snprintf(text, sizeof text, "%016llx", static_cast<unsigned long long>(hash));
  return text;
}

void StateHasher::add_bytes(const void* data, std::size_t size) {
  constexpr std::uint64_t kPrime = 0x100000001b3ull;
  const auto* bytes = static_cast<const unsigned char*>(data);
  std::size_t offset = 0;
  if (size >= 32) {
    // Distinct starting points (splitmix64's constants), so equal blocks in different lanes differ.
    // Four named lanes, not an array: GCC kept an array's lanes on the stack, and each multiply then
    // waited on a store and a reload (17 cycles a block, 76 us of a collision tick at 8640).
    std::uint64_t lane0 = hash_, lane1 = hash_ ^ 0x9e3779b97f4a7c15ull, lane2 = hash_ ^ 0xbf58476d1ce4e5b9ull, lane3 = hash_ ^ 0x94d049bb133111ebull;
    const auto word_at = [bytes](std::size_t at) {
      std::uint64_t word;
      std::memcpy(&word, bytes + at, 8);
      return word;
    };
    for (; offset + 32 <= size; offset += 32) {
      lane0 = (lane0 ^ word_at(offset)) * kPrime;
      lane1 = (lane1 ^ word_at(offset + 8)) * kPrime;
      lane2 = (lane2 ^ word_at(offset + 16)) * kPrime;
      lane3 = (lane3 ^ word_at(offset + 24)) * kPrime;
    }
    hash_ = lane0;
    for (const std::uint64_t lane : {lane1, lane2, lane3}) hash_ = (hash_ ^ lane) * kPrime;
  }
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
