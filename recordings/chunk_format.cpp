// Chunk framing, CRCs and the resynchronising scan of a recording (layout in recordings/README.md).
#include "recordings/chunk_format.h"

#include <algorithm>
#include <cstdio>
#include <cstring>

#include <zlib.h>

#include "recordings/byte_io.h"

namespace resecto::rec {
namespace {

std::uint32_t load_u32(const std::uint8_t* p) {
  std::uint32_t v;
  std::memcpy(&v, p, 4);
  return v;
}

/// What the bytes at `pos` hold, checked in the order a reader trusts them: the marker, the frame's
/// CRC (so a damaged length is never used), a plausible length inside `limit`, the payload's CRC.
enum class ChunkCheck { kNoMarker, kFrameCrcFails, kTooLong, kCutShort, kPayloadCrcFails, kIntact };

/// Checks the chunk whose marker may be at `pos`; `chunk` is filled from kTooLong on.
ChunkCheck check_chunk_at(ByteWindow& file, std::uint64_t limit, std::uint64_t pos, ChunkLocation& chunk) {
  if (pos >= limit || limit - pos < kChunkFrameBytes) return ChunkCheck::kNoMarker;
  const std::span<const std::uint8_t> frame_bytes = file.at(pos, kChunkFrameBytes);
  if (frame_bytes.empty()) return ChunkCheck::kNoMarker;  // unreadable: as if the file ended
  const std::uint8_t* frame = frame_bytes.data();
  if (load_u32(frame) != kChunkMarker) return ChunkCheck::kNoMarker;
  if (crc32_of(std::span<const std::uint8_t>(frame, 16)) != load_u32(frame + 16)) return ChunkCheck::kFrameCrcFails;
  ByteReader reader(std::span<const std::uint8_t>(frame + 4, 12));
  chunk.offset = pos;
  chunk.type = reader.get<std::uint16_t>();
  reader.get<std::uint16_t>();  // flags: none defined yet
  chunk.sequence = reader.get<std::uint32_t>();
  chunk.payload_bytes = reader.get<std::uint32_t>();
  if (chunk.payload_bytes > kMaxChunkPayloadBytes) return ChunkCheck::kTooLong;
  if (limit - pos < kChunkFrameBytes + std::uint64_t{chunk.payload_bytes} + kChunkTrailerBytes) return ChunkCheck::kCutShort;
  const std::span<const std::uint8_t> payload_and_crc = file.at(chunk.payload_offset(), std::size_t{chunk.payload_bytes} + kChunkTrailerBytes);
  if (payload_and_crc.empty()) return ChunkCheck::kCutShort;
  return crc32_of(payload_and_crc.first(chunk.payload_bytes)) == load_u32(payload_and_crc.data() + chunk.payload_bytes)
             ? ChunkCheck::kIntact
             : ChunkCheck::kPayloadCrcFails;
}

/// The chunk whose marker is at `pos`, if its frame is intact (CRC, plausible length, inside the
/// file); `payload_ok` tells whether the payload's CRC holds too.
bool parse_chunk_at(ByteWindow& file, std::uint64_t limit, std::uint64_t pos, ChunkLocation& chunk,
                    bool& payload_ok) {
  const ChunkCheck check = check_chunk_at(file, limit, pos, chunk);
  payload_ok = check == ChunkCheck::kIntact;
  return check == ChunkCheck::kIntact || check == ChunkCheck::kPayloadCrcFails;
}

}  // namespace

std::string_view chunk_type_name(std::uint16_t type) {
  switch (static_cast<ChunkType>(type)) {
    case ChunkType::kHeader: return "header";
    case ChunkType::kTicks: return "ticks";
    case ChunkType::kCommands: return "commands";
    case ChunkType::kSteps: return "steps";
    case ChunkType::kKeyframe: return "keyframe";
    case ChunkType::kSummary: return "summary";
    case ChunkType::kIndex: return "index";
  }
  return "unknown";
}

std::uint32_t crc32_of(std::span<const std::uint8_t> bytes) {
  return static_cast<std::uint32_t>(::crc32(::crc32(0L, Z_NULL, 0), bytes.data(), static_cast<uInt>(bytes.size())));
}

void append_chunk(std::vector<std::uint8_t>& out, ChunkType type, std::uint32_t sequence, std::span<const std::uint8_t> payload) {
  const std::size_t frame_at = out.size();
  ByteWriter w(out);
  w.put(kChunkMarker);
  w.put(static_cast<std::uint16_t>(type));
  w.put(std::uint16_t{0});
  w.put(sequence);
  w.put(static_cast<std::uint32_t>(payload.size()));
  w.put(crc32_of(std::span<const std::uint8_t>(out.data() + frame_at, 16)));
  w.put_bytes(payload);
  w.put(crc32_of(payload));
}

std::string describe_chunk_at(const RecordingBytes& bytes, std::uint64_t pos) {
  if (pos >= bytes.size()) return "the end of the file";
  ByteWindow file(bytes);
  ChunkLocation chunk;
  const ChunkCheck check = check_chunk_at(file, file.size(), pos, chunk);
  const std::string a_chunk = "a " + std::string(chunk_type_name(chunk.type)) + " chunk";
  const std::string claims = a_chunk + " whose frame claims " + std::to_string(chunk.payload_bytes) + " bytes";
  switch (check) {
    case ChunkCheck::kNoMarker: return "no chunk marker";
    case ChunkCheck::kFrameCrcFails: return "a chunk frame whose own CRC fails";
    case ChunkCheck::kTooLong: return claims + ", past any real chunk";
    case ChunkCheck::kCutShort: return claims + ", but the file ends at byte " + std::to_string(file.size()) + " (cut short)";
    case ChunkCheck::kPayloadCrcFails: return a_chunk + " whose payload CRC fails";
    case ChunkCheck::kIntact: break;
  }
  return a_chunk + " (" + std::to_string(chunk.payload_bytes) + " bytes)";
}

std::string describe(const DamagedRange& range) {
  char text[256];
  if (range.frame_intact) {
    std::snprintf(text, sizeof text, "%s chunk %u at byte %llu (%llu bytes): payload CRC mismatch",
                  std::string(chunk_type_name(range.type)).c_str(), range.sequence, static_cast<unsigned long long>(range.offset),
                  static_cast<unsigned long long>(range.bytes));
  } else {
    std::snprintf(text, sizeof text, "%llu bytes at byte %llu hold no intact chunk (a damaged frame, or a chunk cut off)",
                  static_cast<unsigned long long>(range.bytes), static_cast<unsigned long long>(range.offset));
  }
  return text;
}

ChunkScan scan_chunks(const RecordingBytes& bytes, std::size_t window_bytes) {
  ByteWindow file(bytes, window_bytes);
  ChunkScan scan;
  scan.file_bytes = file.size();
  std::uint64_t pos = 0;
  if (const auto signature = file.at(0, sizeof kFileSignature);
      !signature.empty() && std::memcmp(signature.data(), kFileSignature, sizeof kFileSignature) == 0) {
    scan.signature_ok = true;
    pos = sizeof kFileSignature;
  }
  // A clean close leaves a trailer naming the index chunk; the scan then stops before the trailer.
  std::uint64_t limit = file.size();
  const std::span<const std::uint8_t> trailer =
      file.size() >= sizeof kFileSignature + kFileTrailerBytes ? file.at(file.size() - kFileTrailerBytes, kFileTrailerBytes) : std::span<const std::uint8_t>();
  if (!trailer.empty() && std::memcmp(trailer.data() + 8, kTrailerMagic, sizeof kTrailerMagic) == 0) {
    std::uint64_t index_at = 0;
    std::memcpy(&index_at, trailer.data(), 8);
    ChunkLocation index;
    bool payload_ok = false;
    const std::uint64_t body = file.size() - kFileTrailerBytes;
    if (index_at < body && parse_chunk_at(file, body, index_at, index, payload_ok) && payload_ok &&
        index.type == static_cast<std::uint16_t>(ChunkType::kIndex) && index.end() == body) {
      scan.trailer_present = true;
      limit = body;
    }
  }

  std::uint64_t garbage_from = pos;  // start of bytes not yet accounted for by an intact chunk
  bool in_garbage = false;
  auto close_garbage = [&](std::uint64_t end) {
    if (in_garbage && end > garbage_from) scan.damaged.push_back({garbage_from, end - garbage_from, 0, 0, false});
    in_garbage = false;
  };
  std::uint64_t last_end = pos;
  while (pos < limit) {
    ChunkLocation chunk;
    bool payload_ok = false;
    if (parse_chunk_at(file, limit, pos, chunk, payload_ok)) {
      close_garbage(pos);
      if (payload_ok) {
        scan.chunks.push_back(chunk);
      } else {
        // The frame's CRC vouches for the length, so only this chunk is lost and the next one
        // starts right after it.
        scan.damaged.push_back({pos, chunk.end() - pos, chunk.type, chunk.sequence, true});
      }
      pos = chunk.end();
      last_end = pos;
      continue;
    }
    if (!in_garbage) {
      in_garbage = true;
      garbage_from = pos;
    }
    // Resynchronise: the next byte that could start a marker, searched a block at a time.
    std::uint64_t from = pos + 1;
    pos = limit;
    while (from < limit) {
      const std::span<const std::uint8_t> block = file.at(from, static_cast<std::size_t>(std::min<std::uint64_t>(file.block_bytes(), limit - from)));
      if (block.empty()) break;  // unreadable: as if the file ended
      if (const auto* next = static_cast<const std::uint8_t*>(std::memchr(block.data(), kChunkMarker & 0xff, block.size()))) {
        pos = from + static_cast<std::uint64_t>(next - block.data());
        break;
      }
      from += block.size();
    }
  }
  close_garbage(limit);
  scan.tail_bytes = limit - last_end;
  return scan;
}

}  // namespace resecto::rec
