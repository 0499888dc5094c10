// Chunk appending, the index and the trailer, with POSIX writes so flush and sync mean what they say.
#include "recordings/recording_writer.h"

#include <cerrno>
#include <cstdio>
#include <cstring>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include "recordings/byte_io.h"
#include "rtcore/base/atomic_file.h"

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

void append_index_and_trailer(std::vector<std::uint8_t>& out, std::uint64_t out_offset, std::span<const IndexEntry> entries,
                              std::uint32_t sequence) {
  std::vector<std::uint8_t> payload;
  encode_index(entries, payload);
  const std::uint64_t index_at = out_offset + out.size();
  append_chunk(out, ChunkType::kIndex, sequence, payload);
  ByteWriter w(out);
  w.put(index_at);
  w.put_bytes(kTrailerMagic);
}

RecordingWriter::~RecordingWriter() {
  // Not closed (an error left the run, or it is unwinding): the partial file stays for `rec recover`.
  if (fd_ >= 0) ::close(fd_);
}

Error RecordingWriter::fail(const std::string& what, int error_number) {
  if (first_error_.empty()) first_error_ = partial_ + ": " + what + ": " + std::strerror(error_number);
  return Error{first_error_};
}

Result<std::filesystem::path> partial_recording_path(const std::filesystem::path& target) {
  Result<std::filesystem::path> destination = resolve_links(target);
  if (!destination) return Error{destination.error()};
  return std::filesystem::path(destination->string() + ".partial");
}

Status check_partial_recording_path(const std::filesystem::path& target, std::span<const std::filesystem::path> inputs) {
  Result<std::filesystem::path> partial = partial_recording_path(target);
  if (!partial) return Error{partial.error()};
  struct stat existing {};
  if (::lstat(partial->c_str(), &existing) != 0) return Ok{};  // nothing there: the usual case
  if (!S_ISREG(existing.st_mode)) {
    return Error{partial->string() + ": not a regular file (a link, folder or device) where the recording to " + target.string() +
                 " streams until it is closed: move it away"};
  }
  for (const std::filesystem::path& input : inputs) {
    std::error_code error;
    if (!input.empty() && std::filesystem::equivalent(input, *partial, error) && !error) {
      return Error{partial->string() + ": is the input " + input.string() + "; recording to " + target.string() +
                   " streams into it and would destroy it (give another output path)"};
    }
  }
  return Ok{};
}

Status RecordingWriter::open(const std::filesystem::path& target) {
  target_ = target.string();
  Result<std::filesystem::path> destination = resolve_links(target);
  if (!destination) return Error{destination.error()};
  destination_ = destination->string();
  partial_ = destination_ + ".partial";
  first_error_.clear();
  if (Status usable = check_partial_recording_path(target); !usable) {
    first_error_ = usable.error();
    return usable;
  }
  // No link followed and no FIFO waited on, should one appear after the check.
  fd_ = ::open(partial_.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC | O_NOFOLLOW | O_NONBLOCK, 0644);
  if (fd_ < 0) return fail("cannot create the recording", errno);
  struct stat opened {};
  if (::fstat(fd_, &opened) != 0 || !S_ISREG(opened.st_mode)) return fail("cannot create the recording", EINVAL);
  // The recording replaces the target's contents, not its permissions (as AtomicFile keeps them).
  struct stat existing {};
  if (::stat(destination_.c_str(), &existing) == 0 && S_ISREG(existing.st_mode) && ::fchmod(fd_, existing.st_mode & 07777) != 0) {
    return fail("cannot set the permissions", errno);
  }
  pending_.assign(std::begin(kFileSignature), std::end(kFileSignature));
  return flush();
}

void RecordingWriter::add_chunk(ChunkType type, std::span<const std::uint8_t> payload, std::uint64_t first_tick) {
  index_.push_back({bytes_written(), static_cast<std::uint16_t>(type), next_sequence_, first_tick, static_cast<std::uint32_t>(payload.size())});
  append_chunk(pending_, type, next_sequence_++, payload);
}

Status RecordingWriter::flush() {
  // After a failure the file ends somewhere inside a chunk: appending more would only bury it.
  if (!first_error_.empty()) return Error{first_error_};
  std::size_t done = 0;
  while (done < pending_.size()) {
    const ssize_t n = ::write(fd_, pending_.data() + done, pending_.size() - done);
    if (n < 0) {
      if (errno == EINTR) continue;
      return fail("write failed", errno);
    }
    done += static_cast<std::size_t>(n);
  }
  file_offset_ += pending_.size();
  pending_.clear();
  return Ok{};
}

Status RecordingWriter::sync() {
  if (Status flushed = flush(); !flushed) return flushed;
  if (::fdatasync(fd_) != 0) return fail("fdatasync failed", errno);
  return Ok{};
}

Status RecordingWriter::close() {
  if (fd_ < 0) {
    if (first_error_.empty()) return Ok{};
    return Error{first_error_};
  }
  append_index_and_trailer(pending_, file_offset_, index_, next_sequence_++);
  Status status = sync();
  if (::close(fd_) != 0 && status) status = fail("close failed", errno);
  fd_ = -1;
  if (status && std::rename(partial_.c_str(), destination_.c_str()) != 0) status = fail("cannot rename it to " + destination_, errno);
  if (status) return Ok{};
  // The old recording is whole; the new one is as far as it got, which `rec recover` can mend.
  first_error_ =
      status.error() + "; " + target_ + " was left as it was: the recording made is in " + partial_ + " (`resecto rec recover` mends it)";
  return Error{first_error_};
}

}  // namespace resecto::rec
