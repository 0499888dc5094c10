// AtomicFile over POSIX calls: std::ofstream cannot say why a write failed, cannot fsync, and
// reports a failed close only through a stream state nobody checks.
#include "rtcore/base/atomic_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstring>

namespace resecto {
namespace {

/// A name no other writer in this or another process picks: pid plus a process-wide counter.
std::filesystem::path temporary_beside(const std::filesystem::path& target) {
  static std::atomic<unsigned> counter{0};
  // Appended piece by piece: GCC 12 at -O3 takes a `"." + string + ...` chain for an overlapping
  // memcpy (a -Wrestrict false positive, GCC bug 105329).
  std::string leaf = ".";
  leaf += target.filename().string();
  leaf += '.';
  leaf += std::to_string(::getpid());
  leaf += '.';
  leaf += std::to_string(counter.fetch_add(1));
  leaf += ".tmp";
  return target.parent_path() / leaf;
}

/// Creates a new temporary beside `target` (never another writer's) and names it in `created`: its
/// descriptor, or -1 with errno set (EEXIST: no free name was found).
int create_temporary_beside(const std::filesystem::path& target, std::filesystem::path& created) {
  for (int attempt = 0; attempt < 16; ++attempt) {
    created = temporary_beside(target);
    const int fd = ::open(created.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
    if (fd >= 0 || errno != EEXIST) return fd;
  }
  errno = EEXIST;
  return -1;
}

/// Whether `path` lies under /dev or /proc, where a name stands for a device, a process or an open
/// descriptor (/dev/stdout is a link to /proc/self/fd/1), never a file of the user's.
bool names_a_system_object(const std::filesystem::path& path) {
  const std::filesystem::path absolute = std::filesystem::absolute(path).lexically_normal();
  auto element = absolute.begin();
  if (element == absolute.end() || ++element == absolute.end()) return false;
  return *element == "dev" || *element == "proc";
}

}  // namespace

Result<std::filesystem::path> resolve_links(const std::filesystem::path& target) {
  std::filesystem::path path = target;
  for (int hops = 0; hops < 40; ++hops) {
    struct stat link {};
    if (::lstat(path.c_str(), &link) != 0 || !S_ISLNK(link.st_mode)) return path;
    if (names_a_system_object(path)) {
      return Error{target.string() + ": is a link to a device or an open file (" + path.string() + "), not a regular file; not replaced"};
    }
    std::error_code error;
    const std::filesystem::path named = std::filesystem::read_symlink(path, error);
    if (error) return Error{target.string() + ": cannot read the link " + path.string() + ": " + error.message()};
    path = named.is_absolute() ? named : path.parent_path() / named;
  }
  return Error{target.string() + ": too many levels of symbolic links"};
}

namespace {

/// The checks every output path gets: a file name, and only a regular file in the way (renaming over
/// a device or a folder would destroy it), `target` being the path with its links followed.
/// `stat_errno` is 0 when the target exists (`existing` is its stat), else stat's errno.
Status inspect_target(const std::filesystem::path& target, struct stat& existing, int& stat_errno) {
  if (target.empty()) return Error{"an output path is empty"};
  if (target.filename().empty() || target.filename() == "." || target.filename() == "..") {
    return Error{target.string() + ": names a folder, not a file"};
  }
  stat_errno = ::stat(target.c_str(), &existing) == 0 ? 0 : errno;
  if (stat_errno != 0) return Ok{};
  if (S_ISDIR(existing.st_mode)) return Error{target.string() + ": is a folder; not replaced"};
  if (!S_ISREG(existing.st_mode)) return Error{target.string() + ": is not a regular file (a device or pipe); not replaced"};
  return Ok{};
}

}  // namespace

AtomicFile::~AtomicFile() { discard(); }

Error AtomicFile::failure(const std::string& what, int error_number) {
  if (first_error_.empty()) first_error_ = target_.string() + ": " + what + ": " + std::strerror(error_number);
  return Error{first_error_};
}

Status AtomicFile::open(const std::filesystem::path& target) {
  discard();
  target_ = target;
  first_error_.clear();
  Result<std::filesystem::path> resolved = resolve_links(target);
  if (!resolved) return Error{resolved.error()};
  destination_ = *resolved;
  struct stat existing {};
  int stat_errno = 0;
  if (Status replaceable = inspect_target(destination_, existing, stat_errno); !replaceable) return replaceable;
  keep_mode_ = stat_errno == 0;
  if (keep_mode_) {
    mode_ = static_cast<int>(existing.st_mode & 07777);
  } else if (stat_errno != ENOENT) {
    return failure("cannot inspect the target", stat_errno);
  }
  fd_ = create_temporary_beside(destination_, temporary_);
  if (fd_ < 0) {
    const int error_number = errno;
    temporary_.clear();
    if (error_number == EEXIST) return Error{target.string() + ": cannot pick a temporary name beside it"};
    return failure("cannot create a file in its folder", error_number);
  }
  return Ok{};
}

Status AtomicFile::write(std::string_view bytes) {
  if (!first_error_.empty()) return Error{first_error_};
  if (fd_ < 0) return Error{target_.string() + ": written before it was opened"};
  while (!bytes.empty()) {
    const ssize_t written = ::write(fd_, bytes.data(), bytes.size());
    if (written < 0) {
      if (errno == EINTR) continue;
      return failure("cannot write", errno);
    }
    bytes.remove_prefix(static_cast<std::size_t>(written));
  }
  return Ok{};
}

Status AtomicFile::commit() {
  if (!first_error_.empty()) {
    const Error error{first_error_};
    discard();
    return error;
  }
  if (fd_ < 0) return Error{target_.string() + ": committed before it was opened"};
  // fsync before the rename: otherwise a crash can leave the new name pointing at empty blocks.
  Status status = Ok{};
  if (keep_mode_ && ::fchmod(fd_, static_cast<mode_t>(mode_)) != 0) status = failure("cannot set the permissions", errno);
  if (status && ::fsync(fd_) != 0 && errno != EINVAL) status = failure("cannot write", errno);
  const int fd = fd_;
  fd_ = -1;
  if (::close(fd) != 0 && status) status = failure("cannot write", errno);
  if (status && std::rename(temporary_.c_str(), destination_.c_str()) != 0) status = failure("cannot replace the file", errno);
  if (!status) {
    ::unlink(temporary_.c_str());
    temporary_.clear();
    return status;
  }
  temporary_.clear();
  return Ok{};
}

void AtomicFile::discard() {
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
  if (!temporary_.empty()) ::unlink(temporary_.c_str());
  temporary_.clear();
}

namespace {

/// Whether two paths name one existing file (hard links, symbolic links and `..` included).
bool same_file(const std::filesystem::path& a, const std::filesystem::path& b) {
  std::error_code error;
  return std::filesystem::equivalent(a, b, error) && !error;
}

/// Whether `folder` is a folder this process can create entries in; the error names `output`. A
/// folder it cannot write in (read-only, or another user's) would fail only at the end, after the
/// work the output holds (a long run's report).
Status check_writable_folder(const std::filesystem::path& folder, const std::filesystem::path& output) {
  struct stat parent {};
  if (::stat(folder.c_str(), &parent) != 0) return Error{output.string() + ": its folder " + folder.string() + " does not exist"};
  if (!S_ISDIR(parent.st_mode)) return Error{output.string() + ": " + folder.string() + " is not a folder"};
  if (::access(folder.c_str(), W_OK | X_OK) != 0) {
    return Error{output.string() + ": cannot write in its folder " + folder.string() + ": " + std::strerror(errno)};
  }
  // access() answers from the permission bits, which root passes everywhere; a folder of /proc or
  // /sys, a full inode table or a mount that takes no new files says so only when a file is made.
  // So one is: the writer's own kind of temporary, removed at once.
  std::filesystem::path probe;
  const int fd = create_temporary_beside(folder / output.filename(), probe);
  if (fd < 0) {
    if (errno == EEXIST) return Ok{};  // the folder holds files enough to have no free name: it takes them
    return Error{output.string() + ": cannot create a file in its folder " + folder.string() + ": " + std::strerror(errno)};
  }
  ::close(fd);
  ::unlink(probe.c_str());
  return Ok{};
}

}  // namespace

Status check_output_folder(const std::filesystem::path& output, const std::string& what) {
  std::error_code error;
  const std::filesystem::file_status status = std::filesystem::status(output, error);
  if (std::filesystem::exists(status)) {
    if (!std::filesystem::is_directory(status)) return Error{output.string() + ": is a file; " + what};
    return check_writable_folder(output, output);
  }
  // Missing folders are made on the way down: the nearest one that exists must take them.
  std::filesystem::path ancestor = std::filesystem::absolute(output).parent_path();
  while (!std::filesystem::exists(ancestor, error) && ancestor.has_relative_path()) ancestor = ancestor.parent_path();
  return check_writable_folder(ancestor, output);
}

Status check_output_path(const std::filesystem::path& output, std::span<const std::filesystem::path> inputs) {
  Result<std::filesystem::path> resolved = resolve_links(output);
  if (!resolved) return Error{resolved.error()};
  struct stat existing {};
  int stat_errno = 0;
  if (Status replaceable = inspect_target(*resolved, existing, stat_errno); !replaceable) {
    return *resolved == output ? replaceable : Error{output.string() + " (a link to " + resolved->string() + "): " + replaceable.error()};
  }
  if (stat_errno == 0) {
    for (const std::filesystem::path& input : inputs) {
      if (!input.empty() && same_file(input, output)) {
        return Error{output.string() + ": is the input " + input.string() + "; writing it would destroy it (give another output path)"};
      }
    }
  } else if (stat_errno != ENOENT && stat_errno != ENOTDIR) {  // ENOTDIR: a file where its folder should be, named below
    return Error{output.string() + ": cannot inspect: " + std::strerror(stat_errno)};
  }
  return check_writable_folder(resolved->parent_path().empty() ? std::filesystem::path(".") : resolved->parent_path(), output);
}

bool names_one_file(const std::filesystem::path& a, const std::filesystem::path& b) {
  std::error_code error;
  const std::filesystem::path absolute_a = std::filesystem::absolute(a, error);
  if (!error && absolute_a.lexically_normal() == std::filesystem::absolute(b, error).lexically_normal() && !error) return true;
  return same_file(a, b);
}

Status check_output_paths(std::span<const std::filesystem::path> outputs, std::span<const std::filesystem::path> inputs) {
  for (std::size_t i = 0; i < outputs.size(); ++i) {
    if (outputs[i].empty()) continue;
    if (Status ok = check_output_path(outputs[i], inputs); !ok) return ok;
    for (std::size_t j = 0; j < i; ++j) {
      // Two outputs on one path: compared as written and, when the file exists, as files.
      if (!outputs[j].empty() && names_one_file(outputs[j], outputs[i])) {
        return Error{outputs[i].string() + ": given for two outputs; the second would replace the first"};
      }
    }
  }
  return Ok{};
}

Status write_file_atomically(const std::filesystem::path& target, std::string_view bytes) {
  AtomicFile file;
  if (Status opened = file.open(target); !opened) return opened;
  if (Status written = file.write(bytes); !written) return written;
  return file.commit();
}

Status flush_standard_output() {
  // A write error on stdout sticks in its error flag; fflush reports one still in the buffer.
  if (std::fflush(stdout) != 0 || std::ferror(stdout)) {
    const int error_number = errno;
    return Error{std::string("cannot write to standard output: ") + std::strerror(error_number != 0 ? error_number : EIO)};
  }
  return Ok{};
}

}  // namespace resecto
