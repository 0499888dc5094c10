// StateHasher: word-wise FNV-1a (four lanes over 32-byte blocks) checked against the definition
// written out, and the properties the determinism checks rely on (order, length and every bit count).
#include "rtcore/base/state_hash.h"

#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <utility>
#include <vector>

namespace resecto {
namespace {

constexpr std::uint64_t kOffset = 0xcbf29ce484222325ull;
constexpr std::uint64_t kPrime = 0x100000001b3ull;

TEST(StateHasher, IsWordWiseFnv1aWithTheLengthMixedInLast) {
  StateHasher empty;
  EXPECT_EQ(empty.value(), kOffset);
  const std::array<std::uint64_t, 2> words = {0x0123456789abcdefull, 42};
  StateHasher hasher;
  hasher.add(std::span<const std::uint64_t>(words));
  std::uint64_t expected = kOffset;
  for (std::uint64_t w : words) expected = (expected ^ w) * kPrime;
  expected = (expected ^ 16u) * kPrime;
  EXPECT_EQ(hasher.value(), expected);
  // A tail shorter than a word is zero-padded; its length still tells it from the padded word.
  const std::array<std::uint8_t, 3> tail = {1, 2, 3};
  StateHasher short_hasher;
  short_hasher.add(std::span<const std::uint8_t>(tail));
  EXPECT_EQ(short_hasher.value(), ((kOffset ^ 0x030201u) * kPrime ^ 3u) * kPrime);
  const std::array<std::uint8_t, 4> padded = {1, 2, 3, 0};
  StateHasher padded_hasher;
  padded_hasher.add(std::span<const std::uint8_t>(padded));
  EXPECT_NE(short_hasher.value(), padded_hasher.value());
}

TEST(StateHasher, LongSpansRunFourLanesThenTheRestAsOne) {
  // 5 words: one 32-byte block in four lanes, folded; then the fifth word and the length.
  const std::array<std::uint64_t, 5> words = {11, 22, 33, 44, 55};
  StateHasher hasher;
  hasher.add(std::span<const std::uint64_t>(words));
  std::uint64_t lanes[4] = {kOffset, kOffset ^ 0x9e3779b97f4a7c15ull, kOffset ^ 0xbf58476d1ce4e5b9ull, kOffset ^ 0x94d049bb133111ebull};
  for (int k = 0; k < 4; ++k) lanes[k] = (lanes[k] ^ words[static_cast<std::size_t>(k)]) * kPrime;
  std::uint64_t expected = lanes[0];
  for (int k = 1; k < 4; ++k) expected = (expected ^ lanes[k]) * kPrime;
  expected = (expected ^ words[4]) * kPrime;
  expected = (expected ^ 40u) * kPrime;
  EXPECT_EQ(hasher.value(), expected);
}

TEST(StateHasher, ManyBlocksKeepEachLaneOnItsOwnWordsAndTheTailAfter) {
  // 1,000 blocks and 13 bytes more, against the definition written out lane by lane.
  std::vector<std::uint8_t> bytes(32 * 1000 + 13);
  for (std::size_t i = 0; i < bytes.size(); ++i) bytes[i] = static_cast<std::uint8_t>(i * 131 + 7);
  StateHasher hasher;
  hasher.add(std::span<const std::uint8_t>(bytes));
  const auto word_at = [&](std::size_t at, std::size_t length) {
    std::uint64_t word = 0;
    for (std::size_t b = 0; b < length; ++b) word |= static_cast<std::uint64_t>(bytes[at + b]) << (8 * b);
    return word;
  };
  std::uint64_t lanes[4] = {kOffset, kOffset ^ 0x9e3779b97f4a7c15ull, kOffset ^ 0xbf58476d1ce4e5b9ull, kOffset ^ 0x94d049bb133111ebull};
  std::size_t at = 0;
  for (; at + 32 <= bytes.size(); at += 32) {
    for (std::size_t k = 0; k < 4; ++k) lanes[k] = (lanes[k] ^ word_at(at + 8 * k, 8)) * kPrime;
  }
  std::uint64_t expected = lanes[0];
  for (int k = 1; k < 4; ++k) expected = (expected ^ lanes[k]) * kPrime;
  expected = (expected ^ word_at(at, 8)) * kPrime;  // one whole word, then 5 bytes zero-padded
  expected = (expected ^ word_at(at + 8, 5)) * kPrime;
  expected = (expected ^ bytes.size()) * kPrime;
  EXPECT_EQ(hasher.value(), expected);
}

TEST(StateHasher, LongSpansSeeEveryBitAndWhichLaneAWordIsIn) {
  std::vector<std::uint64_t> words(64);
  for (std::size_t i = 0; i < words.size(); ++i) words[i] = 0x9e3779b97f4a7c15ull * (i + 1);
  StateHasher reference;
  reference.add(std::span<const std::uint64_t>(words));
  for (std::size_t i : {std::size_t{0}, std::size_t{1}, std::size_t{2}, std::size_t{3}, std::size_t{37}, std::size_t{63}}) {
    for (int bit : {0, 31, 63}) {
      std::vector<std::uint64_t> flipped = words;
      flipped[i] ^= 1ull << bit;
      StateHasher h;
      h.add(std::span<const std::uint64_t>(flipped));
      EXPECT_NE(h.value(), reference.value()) << "word " << i << " bit " << bit;
    }
  }
  std::vector<std::uint64_t> swapped = words;  // two words of one block, in different lanes
  std::swap(swapped[4], swapped[5]);
  StateHasher h;
  h.add(std::span<const std::uint64_t>(swapped));
  EXPECT_NE(h.value(), reference.value());
}

TEST(StateHasher, SeesOrderAndEveryBit) {
  const std::vector<double> a = {1.0, 2.0, 3.0};
  const std::vector<double> swapped = {2.0, 1.0, 3.0};
  StateHasher ha, hs;
  ha.add(std::span<const double>(a));
  hs.add(std::span<const double>(swapped));
  EXPECT_NE(ha.value(), hs.value());
  for (int bit = 0; bit < 64; ++bit) {
    std::uint64_t word = 0x5555aaaa5555aaaaull;
    StateHasher before, after;
    before.add(std::span<const std::uint64_t>(&word, 1));
    word ^= 1ull << bit;
    after.add(std::span<const std::uint64_t>(&word, 1));
    EXPECT_NE(before.value(), after.value()) << "bit " << bit;
  }
}

}  // namespace
}  // namespace resecto
