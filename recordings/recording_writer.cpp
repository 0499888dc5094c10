// Chunk appending, the index and the trailer, with POSIX writes so flush and sync mean what they say.
#include "recordings/recording_writer.h"

#include <cerrno>
#include <cstring>

#include <fcntl.h>
#include <unistd.h>

#include "recordings/byte_io.h"

namespace resecto::rec {

void encode_index(std::span<const IndexEntry> entries, std::vector<std::uint8_t>& payload) {
  payload.clear();
  ByteWriter w(payload);
  w.put(static_cast<std::uint32_t>(entries.size()));
  for (const IndexEntry& e : entries) {
    w.put(e.offset);
    w.put(e.type);
    w.put(e.sequence);
    w.put(e.first_tick);
    w.put(e.payload_bytes);
  }
}

Result<std::vector<IndexEntry>> decode_index(std::span<const std::uint8_t> payload) {
  constexpr std::uint64_t kEntryBytes = 8 + 2 + 4 + 8 + 4;
  ByteReader r(payload);
  const std::uint32_t count = r.get<std::uint32_t>();
  if (!r.ok() || count * kEntryBytes != r.remaining()) return Error{"index: count and length disagree"};
  std::vector<IndexEntry> entries(count);
  for (IndexEntry& e : entries) {
    e.offset = r.get<std::uint64_t>();
    e.type = r.get<std::uint16_t>();
    e.sequence = r.get<std::uint32_t>();
    e.first_tick = r.get<std::uint64_t>();
    e.payload_bytes = r.get<std::uint32_t>();
  }
  return entries;
}

RecordingWriter::~RecordingWriter() {
  if (fd_ >= 0) ::close(fd_);
}

Status RecordingWriter::open(const std::filesystem::path& path) {
  path_ = path.string();
  fd_ = ::open(path_.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd_ < 0) return Error{path_ + ": cannot create the recording: " + std::strerror(errno)};
  pending_.assign(std::begin(kFileSignature), std::end(kFileSignature));
  return flush();
}

void RecordingWriter::add_chunk(ChunkType type, std::span<const std::uint8_t> payload, std::uint64_t first_tick) {
  index_.push_back({bytes_written(), static_cast<std::uint16_t>(type), next_sequence_, first_tick, static_cast<std::uint32_t>(payload.size())});
  append_chunk(pending_, type, next_sequence_++, payload);
}

Status RecordingWriter::flush() {
  std::size_t done = 0;
  while (done < pending_.size()) {
    const ssize_t n = ::write(fd_, pending_.data() + done, pending_.size() - done);
    if (n < 0) {
      if (errno == EINTR) continue;
      return Error{path_ + ": write failed: " + std::strerror(errno)};
    }
    done += static_cast<std::size_t>(n);
  }
  file_offset_ += pending_.size();
  pending_.clear();
  return Ok{};
}

Status RecordingWriter::sync() {
  if (Status flushed = flush(); !flushed) return flushed;
  if (::fdatasync(fd_) != 0) return Error{path_ + ": fdatasync failed: " + std::strerror(errno)};
  return Ok{};
}

Status RecordingWriter::close() {
  if (fd_ < 0) return Ok{};
  std::vector<std::uint8_t> payload;
  encode_index(index_, payload);
  const std::uint64_t index_at = bytes_written();
  append_chunk(pending_, ChunkType::kIndex, next_sequence_++, payload);
  ByteWriter w(pending_);
  w.put(index_at);
  w.put_bytes(kTrailerMagic);
  Status synced = sync();
  ::close(fd_);
  fd_ = -1;
  return synced;
}

}  // namespace resecto::rec
