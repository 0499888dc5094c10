// RecordingWriter: appends framed chunks to a recording file and, on close, the summary, the index
// and the trailer. It writes in place (not to a temporary renamed at the end): a recording exists to
// survive the process, so at every moment the file on disk is valid up to its last whole chunk.
// Single-threaded: the recorder thread owns it; `rec recover` uses it too.
#pragma once

#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

#include "recordings/chunk_format.h"
#include "rtcore/base/result.h"

namespace resecto::rec {

/// One entry of the index chunk.
struct IndexEntry {
  std::uint64_t offset = 0;
  std::uint16_t type = 0;
  std::uint32_t sequence = 0;
  std::uint64_t first_tick = 0;  ///< the first tick a ticks/steps/keyframe chunk covers; 0 otherwise
  std::uint32_t payload_bytes = 0;
};

/// Index payload: u32 count, then per entry offset u64, type u16, sequence u32, first tick u64, payload bytes u32.
void encode_index(std::span<const IndexEntry> entries, std::vector<std::uint8_t>& payload);
Result<std::vector<IndexEntry>> decode_index(std::span<const std::uint8_t> payload);

class RecordingWriter {
 public:
  RecordingWriter() = default;
  ~RecordingWriter();
  RecordingWriter(const RecordingWriter&) = delete;
  RecordingWriter& operator=(const RecordingWriter&) = delete;

  /// Creates (truncates) `path` and writes the signature.
  Status open(const std::filesystem::path& path);
  /// Buffers one chunk; `first_tick` goes into the index.
  void add_chunk(ChunkType type, std::span<const std::uint8_t> payload, std::uint64_t first_tick = 0);
  /// Hands the buffered chunks to the operating system (a killed process then loses nothing more).
  Status flush();
  /// flush() and fdatasync(): on the disk even if the machine loses power.
  Status sync();
  /// Writes the index chunk and trailer, syncs and closes.
  Status close();

  std::uint64_t bytes_written() const { return file_offset_ + pending_.size(); }
  const std::string& path() const { return path_; }

 private:
  int fd_ = -1;
  std::string path_;
  std::uint64_t file_offset_ = 0;  ///< bytes already handed to the OS
  std::vector<std::uint8_t> pending_;
  std::vector<IndexEntry> index_;
  std::uint32_t next_sequence_ = 0;
};

}  // namespace resecto::rec
