// A recording's bytes where they lie. Opened from a file, they stay on disk and are read where a
// reader needs them: holding the whole file cost every reader the file's size in memory (90 MB for a
// 20-minute session, audit 10, finding 5). Bytes handed in (tests, fuzzing) stay in memory.
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "rtcore/base/result.h"

namespace resecto::rec {

class RecordingBytes {
 public:
  /// Opens a regular file for reading (a folder, device or pipe is refused, as read_regular_file
  /// refuses them); its size is fixed at open: a recording still being written is read as far as it
  /// was then.
  static Result<RecordingBytes> open(const std::filesystem::path& path);
  explicit RecordingBytes(std::vector<std::uint8_t> bytes);

  std::uint64_t size() const { return size_; }
  /// Copies the bytes at [offset, offset + out.size()) into `out`; false when the file no longer
  /// holds them (cut shorter since it was opened) or the read failed. Safe from several threads.
  bool read(std::uint64_t offset, std::span<std::uint8_t> out) const;
  /// The bytes themselves when they are in memory; empty for a file.
  std::span<const std::uint8_t> in_memory() const;

 private:
  RecordingBytes() = default;
  struct File;
  std::shared_ptr<const File> file_;
  std::shared_ptr<const std::vector<std::uint8_t>> memory_;
  std::uint64_t size_ = 0;
};

/// A moving window over a RecordingBytes for reading it front to back in blocks (the chunk scan):
/// at(pos, n) returns the n bytes at pos, read from the file only when the window does not hold them.
class ByteWindow {
 public:
  /// Bytes read at a time: a scan's chunks are mostly far smaller, so each read serves many.
  static constexpr std::size_t kDefaultBlockBytes = std::size_t{1} << 20;

  explicit ByteWindow(const RecordingBytes& bytes, std::size_t block_bytes = kDefaultBlockBytes)
      : bytes_(bytes), block_bytes_(block_bytes > 0 ? block_bytes : 1) {}
  /// The `n` bytes at `pos`, valid until the next call; empty when the bytes do not hold them all.
  std::span<const std::uint8_t> at(std::uint64_t pos, std::size_t n);
  std::uint64_t size() const { return bytes_.size(); }
  std::size_t block_bytes() const { return block_bytes_; }

 private:
  const RecordingBytes& bytes_;
  std::size_t block_bytes_;
  std::vector<std::uint8_t> buffer_;
  std::uint64_t buffer_at_ = 0;
};

}  // namespace resecto::rec
