// The recording's container: a file signature, then chunks, each framed by a marker, its type, a
// sequence number, its length and two CRC-32s (one over the frame so a damaged length is never
// trusted, one over the payload), and at the end an index chunk and a fixed trailer pointing at it.
// The byte layout is documented in recordings/README.md; this file is its single definition.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "recordings/recording_bytes.h"

namespace resecto::rec {

/// The file's first 8 bytes, "RSREC\r\n\x1a": the CR LF catches a text-mode transfer and the ^Z
/// stops a DOS `type`, as PNG's signature does.
inline constexpr std::uint8_t kFileSignature[8] = {'R', 'S', 'R', 'E', 'C', '\r', '\n', 0x1a};
/// Bumped on any incompatible change of a chunk's layout.
inline constexpr std::uint32_t kFormatVersion = 1;
/// Every chunk starts with these four bytes ("CHNK" little-endian): the reader resynchronises on them.
inline constexpr std::uint32_t kChunkMarker = 0x4B4E4843u;
/// marker u32, type u16, flags u16, sequence u32, payload length u32, frame CRC u32.
inline constexpr std::size_t kChunkFrameBytes = 20;
/// The payload's CRC u32 after it.
inline constexpr std::size_t kChunkTrailerBytes = 4;
/// A payload longer than this is a damaged length, never allocated: the largest real payload is a
/// keyframe of a million-triangle surface, far below.
inline constexpr std::uint32_t kMaxChunkPayloadBytes = 64u << 20;
/// The file's last 16 bytes when it was closed cleanly: the index chunk's offset u64, then this.
inline constexpr std::uint8_t kTrailerMagic[8] = {'R', 'S', 'C', 'T', 'I', 'N', 'D', 'X'};
inline constexpr std::size_t kFileTrailerBytes = 16;

enum class ChunkType : std::uint16_t {
  kHeader = 1,    ///< JSON: format version, build, the run's configuration
  kTicks = 2,     ///< a run of consecutive ticks' inputs (deflated columns)
  kCommands = 3,  ///< parameter commands with their tick
  kSteps = 4,     ///< collision steps: state hash, tool poses, metrics (deflated columns)
  kKeyframe = 5,  ///< a Draco-compressed tissue surface with node ids
  kSummary = 6,   ///< JSON written at the end: final tick and hash, losses
  kIndex = 7,     ///< every chunk's offset, type, sequence and first tick
};
inline constexpr int kChunkTypeCount = 8;  // index by the enum value; 0 unused

/// The name `rec info` prints, or "unknown".
std::string_view chunk_type_name(std::uint16_t type);

/// zlib's crc32 (the IEEE 802.3 polynomial, as in gzip and PNG). See README: why not CRC-32C.
std::uint32_t crc32_of(std::span<const std::uint8_t> bytes);

/// Appends one framed chunk (frame, payload, payload CRC) to `out`.
void append_chunk(std::vector<std::uint8_t>& out, ChunkType type, std::uint32_t sequence, std::span<const std::uint8_t> payload);

/// A chunk found in a file.
struct ChunkLocation {
  std::uint64_t offset = 0;  ///< of its marker
  std::uint16_t type = 0;
  std::uint32_t sequence = 0;
  std::uint32_t payload_bytes = 0;
  std::uint64_t payload_offset() const { return offset + kChunkFrameBytes; }
  std::uint64_t end() const { return offset + kChunkFrameBytes + payload_bytes + kChunkTrailerBytes; }
};

/// A stretch of bytes that held no intact chunk: a chunk with a bad CRC, or garbage between chunks.
struct DamagedRange {
  std::uint64_t offset = 0;
  std::uint64_t bytes = 0;
  /// The damaged chunk's type and sequence when its frame was intact (only its payload is bad); 0 otherwise.
  std::uint16_t type = 0;
  std::uint32_t sequence = 0;
  bool frame_intact = false;
};

/// What the bytes at `pos` of `bytes` hold, for a reader that expected a chunk there: "a ticks chunk
/// (3601 bytes)", "a header chunk whose frame claims 2335 bytes, but the file ends at byte 1000 (cut
/// short)", "a header chunk whose payload CRC fails", "a chunk frame whose own CRC fails", "no chunk
/// marker", or "the end of the file".
std::string describe_chunk_at(const RecordingBytes& bytes, std::uint64_t pos);

/// One line saying what a damaged range is and where ("keyframe chunk 80 at byte 223687 (3601 bytes):
/// payload CRC mismatch"), as `rec info`, `rec verify` and the keyframe lookup print it.
std::string describe(const DamagedRange& range);

/// What a scan of a whole file found.
struct ChunkScan {
  bool signature_ok = false;
  std::vector<ChunkLocation> chunks;   ///< every intact chunk, in file order
  std::vector<DamagedRange> damaged;   ///< in file order
  bool trailer_present = false;        ///< the file ends with a trailer pointing at an intact index chunk
  std::uint64_t file_bytes = 0;
  /// Bytes after the last intact chunk that form no chunk (a cut file's tail); also in `damaged`
  /// unless zero.
  std::uint64_t tail_bytes = 0;
};

/// Walks the file chunk by chunk, checking both CRCs of each; on a bad frame it searches forward for
/// the next marker, on a bad payload it skips the chunk by its (CRC-checked) length. Never reads
/// outside the file, never allocates from a length field beyond kMaxChunkPayloadBytes; holds
/// `window_bytes` of the file (or the chunk, when larger) at a time.
ChunkScan scan_chunks(const RecordingBytes& bytes, std::size_t window_bytes = ByteWindow::kDefaultBlockBytes);
/// The same over bytes in memory (tests, fuzzing; copied).
inline ChunkScan scan_chunks(std::span<const std::uint8_t> file) {
  return scan_chunks(RecordingBytes(std::vector<std::uint8_t>(file.begin(), file.end())));
}

}  // namespace resecto::rec
