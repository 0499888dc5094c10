// Reading a recording's bytes from its file on demand (pread: no shared file offset, so the console's
// replay thread and its panels may read one recording at once).
#include "recordings/recording_bytes.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>

#include "rtcore/base/text_file.h"

namespace resecto::rec {

struct RecordingBytes::File {
  int fd = -1;
  File() = default;
  File(const File&) = delete;
  File& operator=(const File&) = delete;
  ~File() {
    if (fd >= 0) ::close(fd);
  }
};

Result<RecordingBytes> RecordingBytes::open(const std::filesystem::path& path) {
  const std::string what = " the recording";
  const Result<std::uintmax_t> checked = regular_file_size(path, what, kMaxBinaryFileBytes);
  if (!checked) return Error{checked.error()};
  auto file = std::make_shared<File>();
  // O_NONBLOCK: a pipe put in the file's place after the check above must not hang the open.
  file->fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NOCTTY | O_NONBLOCK);
  if (file->fd < 0) return Error{path.string() + ": cannot open" + what + ": " + std::strerror(errno)};  // e.g. "Permission denied"
  struct stat status {};
  if (::fstat(file->fd, &status) != 0 || !S_ISREG(status.st_mode)) {
    return Error{path.string() + ": not a regular file (a device or pipe is never read whole)"};
  }
  // The size as opened, within the limit regular_file_size checked: a file still growing is read as
  // far as it was then.
  RecordingBytes bytes;
  bytes.file_ = std::move(file);
  bytes.size_ = std::min<std::uint64_t>(static_cast<std::uint64_t>(std::max<off_t>(status.st_size, 0)), *checked);
  return bytes;
}

RecordingBytes::RecordingBytes(std::vector<std::uint8_t> bytes)
    : memory_(std::make_shared<const std::vector<std::uint8_t>>(std::move(bytes))), size_(memory_->size()) {}

std::span<const std::uint8_t> RecordingBytes::in_memory() const {
  return memory_ ? std::span<const std::uint8_t>(*memory_) : std::span<const std::uint8_t>();
}

bool RecordingBytes::read(std::uint64_t offset, std::span<std::uint8_t> out) const {
  if (offset > size_ || out.size() > size_ - offset) return false;
  if (memory_) {
    std::copy_n(memory_->begin() + static_cast<std::ptrdiff_t>(offset), out.size(), out.begin());
    return true;
  }
  std::size_t done = 0;
  while (done < out.size()) {
    const ssize_t got = ::pread(file_->fd, out.data() + done, out.size() - done, static_cast<off_t>(offset + done));
    if (got < 0 && errno == EINTR) continue;
    if (got <= 0) return false;  // an error, or the file was cut shorter since it was opened
    done += static_cast<std::size_t>(got);
  }
  return true;
}

std::span<const std::uint8_t> ByteWindow::at(std::uint64_t pos, std::size_t n) {
  if (pos > bytes_.size() || n > bytes_.size() - pos) return {};
  if (const std::span<const std::uint8_t> memory = bytes_.in_memory(); !memory.empty()) return memory.subspan(pos, n);
  const bool held = pos >= buffer_at_ && pos + n <= buffer_at_ + buffer_.size();
  if (!held) {
    // A block from `pos` on (or the n bytes, when more): the scan moves forward, so what comes next
    // is read with it.
    const std::uint64_t want = std::min<std::uint64_t>(std::max(n, block_bytes_), bytes_.size() - pos);
    buffer_.resize(static_cast<std::size_t>(want));
    buffer_at_ = pos;
    if (!bytes_.read(pos, buffer_)) {
      buffer_.clear();
      return {};
    }
  }
  return std::span<const std::uint8_t>(buffer_).subspan(static_cast<std::size_t>(pos - buffer_at_), n);
}

}  // namespace resecto::rec
