// RecordingWriter: appends framed chunks to a recording file and, on close, the summary, the index
// and the trailer. It streams into TARGET.partial beside the target, valid at every moment up to its
// last whole chunk (a recording exists to survive the process: `rec recover` mends a partial file),
// and renames it over the target only once closed: a run that fails or dies leaves the old recording
// at the target whole. Single-threaded: the recorder thread owns it.
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

/// Appends the index chunk (listing `entries`) and the trailer to `out`, whose first byte is at file
/// offset `out_offset`.
void append_index_and_trailer(std::vector<std::uint8_t>& out, std::uint64_t out_offset, std::span<const IndexEntry> entries,
                              std::uint32_t sequence);

/// The file a recording to `target` streams into until it is closed: the target, links followed, with
/// ".partial" appended.
Result<std::filesystem::path> partial_recording_path(const std::filesystem::path& target);
/// Whether a recording to `target` may stream into its partial file, checked before the run: a stale
/// partial file is replaced, but a link, folder, FIFO or device there is refused (opened blindly, a
/// link's target was overwritten and a FIFO blocked the run for good), and so is one of `inputs` (the
/// partial file of a killed run, opened for replay). Audit 8, G2 and G3.
Status check_partial_recording_path(const std::filesystem::path& target, std::span<const std::filesystem::path> inputs = {});

class RecordingWriter {
 public:
  RecordingWriter() = default;
  ~RecordingWriter();
  RecordingWriter(const RecordingWriter&) = delete;
  RecordingWriter& operator=(const RecordingWriter&) = delete;

  /// Creates (truncates) the partial file beside `target` (links followed, as every output's) and
  /// writes the signature; nothing happens to `target` yet.
  Status open(const std::filesystem::path& target);
  /// Buffers one chunk; `first_tick` goes into the index.
  void add_chunk(ChunkType type, std::span<const std::uint8_t> payload, std::uint64_t first_tick = 0);
  /// Hands the buffered chunks to the operating system (a killed process then loses nothing more).
  /// After a failure nothing more is written and every call reports the first failure again.
  Status flush();
  /// flush() and fdatasync(): on the disk even if the machine loses power.
  Status sync();
  /// Writes the index chunk and trailer, syncs, closes and renames the partial file over the target.
  /// After any failure the target is left as it was and the error says where the partial file is.
  Status close();

  std::uint64_t bytes_written() const { return file_offset_ + pending_.size(); }
  /// The file being written: the target's name with ".partial" appended, in the target's folder.
  const std::string& partial_path() const { return partial_; }

 private:
  /// Remembers the first failure (`what` failed on the partial file) and returns it.
  Error fail(const std::string& what, int error_number);

  int fd_ = -1;
  std::string target_;       ///< as given, for messages
  std::string destination_;  ///< the file replaced: the target with its links followed
  std::string partial_;
  std::string first_error_;
  std::uint64_t file_offset_ = 0;  ///< bytes already handed to the OS
  std::vector<std::uint8_t> pending_;
  std::vector<IndexEntry> index_;
  std::uint32_t next_sequence_ = 0;
};

}  // namespace resecto::rec
