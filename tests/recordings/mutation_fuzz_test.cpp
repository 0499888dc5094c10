// Randomly mutated recordings through the reader: no crash, no hang, no allocation sized by a damaged
// length field. RESECTO_FUZZ_ITERATIONS sets the count (default 2,000; the 100,000 are run
// under the asan preset: RESECTO_FUZZ_ITERATIONS=100000 ctest --preset asan -R Fuzz). Half of the
// mutations repair the CRCs afterwards, so the payload decoders (deflate, JSON, Draco) see hostile
// bytes too, not only the CRC check.
#include <gtest/gtest.h>

#include <cstdlib>
#include <random>

#include "recordings/byte_io.h"
#include "recordings/chunk_format.h"
#include "recordings/recording_reader.h"
#include "tests/recordings/short_recording.h"

namespace resecto::rec {
namespace {

std::uint64_t iterations() {
  const char* text = std::getenv("RESECTO_FUZZ_ITERATIONS");
  return text ? std::strtoull(text, nullptr, 10) : 2000;
}

/// Recomputes both CRCs of every chunk whose frame still parses as one (after a mutation).
void repair_crcs(std::vector<std::uint8_t>& bytes, const ChunkScan& original) {
  for (const ChunkLocation& c : original.chunks) {
    if (c.end() > bytes.size()) continue;
    std::uint32_t length = 0;
    std::memcpy(&length, bytes.data() + c.offset + 12, 4);
    if (length > kMaxChunkPayloadBytes || c.offset + kChunkFrameBytes + length + kChunkTrailerBytes > bytes.size()) continue;
    const std::uint32_t frame_crc = crc32_of(std::span<const std::uint8_t>(bytes.data() + c.offset, 16));
    std::memcpy(bytes.data() + c.offset + 16, &frame_crc, 4);
    const std::uint32_t payload_crc = crc32_of(std::span<const std::uint8_t>(bytes.data() + c.offset + kChunkFrameBytes, length));
    std::memcpy(bytes.data() + c.offset + kChunkFrameBytes + length, &payload_crc, 4);
  }
}

TEST(RecordingFuzz, MutatedFilesNeverCrashTheReader) {
  const std::vector<std::uint8_t>& original = testing::short_recording().file;
  const ChunkScan scan = scan_chunks(original);
  std::mt19937_64 random(20261124);
  const std::uint64_t count = iterations();
  std::uint64_t opened = 0, keyframes_decoded = 0, steps_read = 0;
  for (std::uint64_t i = 0; i < count; ++i) {
    std::vector<std::uint8_t> bytes = original;
    const int mutations = 1 + static_cast<int>(random() % 8);
    for (int m = 0; m < mutations && !bytes.empty(); ++m) {
      const std::size_t at = random() % bytes.size();
      switch (random() % 7) {
        case 0: bytes[at] ^= static_cast<std::uint8_t>(1u << (random() % 8)); break;  // a bit
        case 1: bytes[at] = static_cast<std::uint8_t>(random()); break;                // a byte
        case 2: {                                                                     // a length field, hostile
          const ChunkLocation& c = scan.chunks[random() % scan.chunks.size()];
          const std::uint32_t huge = static_cast<std::uint32_t>(random());
          if (c.offset + 16 <= bytes.size()) std::memcpy(bytes.data() + c.offset + 12, &huge, 4);
          break;
        }
        case 3: bytes.resize(at); break;                                               // a cut
        case 4: bytes.erase(bytes.begin() + static_cast<std::ptrdiff_t>(at),           // a hole
                            bytes.begin() + static_cast<std::ptrdiff_t>(std::min(bytes.size(), at + 1 + random() % 64)));
          break;
        case 5: {                                                                     // a run of bytes in a payload
          const std::size_t n = std::min<std::size_t>(bytes.size() - at, 1 + random() % 16);
          for (std::size_t k = 0; k < n; ++k) bytes[at + k] = static_cast<std::uint8_t>(random());
          break;
        }
        default: {                                                                    // a chunk duplicated
          const ChunkLocation& c = scan.chunks[random() % scan.chunks.size()];
          if (c.end() <= bytes.size()) {
            std::vector<std::uint8_t> copy(bytes.begin() + static_cast<std::ptrdiff_t>(c.offset), bytes.begin() + static_cast<std::ptrdiff_t>(c.end()));
            bytes.insert(bytes.begin() + static_cast<std::ptrdiff_t>(std::min(at, bytes.size())), copy.begin(), copy.end());
          }
        }
      }
    }
    if (random() % 2 == 0) repair_crcs(bytes, scan);
    Result<Recording> r = Recording::from_bytes(std::move(bytes));
    if (!r) continue;
    ++opened;
    // Whatever opened must be internally consistent and browsable.
    std::uint64_t covered = 0;
    for (const ChunkLocation& c : r->chunks()) covered += c.end() - c.offset;
    for (const DamagedRange& d : r->damaged()) covered += d.bytes;
    EXPECT_LE(covered, r->file_bytes());
    for (std::size_t k = 0; k < r->keyframes().size(); ++k) {
      if (r->decode_keyframe(k)) ++keyframes_decoded;
    }
    for (std::size_t k = 0; k < 3; ++k) (void)r->keyframe_at_time(0.1 * static_cast<double>(k));
    // Every step and tick it kept reads back from its chunk as the open found it.
    const Result<std::vector<StepRecord>> steps = r->all_steps();
    ASSERT_TRUE(steps) << "mutation " << i << ": " << steps.error();
    ASSERT_EQ(steps->size(), r->steps().size());
    for (std::size_t s = 0; s < steps->size(); ++s) {
      ASSERT_EQ((*steps)[s].tick, r->steps()[s].tick) << "mutation " << i;
      ASSERT_EQ((*steps)[s].state_hash, r->steps()[s].state_hash) << "mutation " << i;
    }
    steps_read += steps->size();
    TickReader ticks(*r);
    std::uint64_t ticks_read = 0;
    while (ticks.next() != nullptr) ++ticks_read;
    ASSERT_EQ(ticks_read, r->tick_count()) << "mutation " << i;
  }
  std::printf("%llu mutated recordings: %llu opened, %llu keyframes decoded, %llu steps read\n", static_cast<unsigned long long>(count),
              static_cast<unsigned long long>(opened), static_cast<unsigned long long>(keyframes_decoded), static_cast<unsigned long long>(steps_read));
  EXPECT_GT(opened, 0u);
}

}  // namespace
}  // namespace resecto::rec
