// The one way Resecto writes an output file: to a temporary file beside the target, every write and
// the close checked, fsync'd, then renamed over the target. A failure (full disk, no permission, a
// folder or device in the way) leaves the old file untouched and no temporary behind.
#pragma once

#include <filesystem>
#include <span>
#include <string>
#include <string_view>

#include "rtcore/base/result.h"

namespace resecto {

/// An output file being written. Nothing appears at the target until commit() succeeds; destroying
/// an uncommitted file removes its temporary.
class AtomicFile {
 public:
  AtomicFile() = default;
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;
  ~AtomicFile();

  /// Creates the temporary beside `target`, or beside the file it names if it is a symbolic link
  /// (the link stays; its file is replaced). Fails if the target exists and is not a regular file,
  /// or is a link into /dev or /proc (/dev/stdout).
  Status open(const std::filesystem::path& target);
  /// Appends bytes; after the first failure every later call reports it again.
  Status write(std::string_view bytes);
  /// Flushes to disk, closes and renames over the target; the target keeps its permission bits.
  Status commit();
  /// Removes the temporary without touching the target.
  void discard();

  bool is_open() const { return fd_ >= 0; }
  const std::filesystem::path& target() const { return target_; }

 private:
  Error failure(const std::string& what, int error_number);

  std::filesystem::path target_;       // as given, for messages
  std::filesystem::path destination_;  // the file replaced: the target with its links followed
  std::filesystem::path temporary_;
  int fd_ = -1;
  int mode_ = 0666;  // the replaced file's permission bits, or the umask's default
  bool keep_mode_ = false;
  std::string first_error_;
};

/// The file an output at `target` really is: a symbolic link is followed to the file it names (so
/// the link stays a link and its file is the one replaced), link by link, each relative link from its
/// own folder. A link into /dev or /proc (/dev/stdout, /proc/self/fd/1) is refused: renaming over it
/// would destroy the system's link, and its file may be a pipe or a terminal.
Result<std::filesystem::path> resolve_links(const std::filesystem::path& target);

/// Writes `bytes` as the whole of `target` through an AtomicFile.
Status write_file_atomically(const std::filesystem::path& target, std::string_view bytes);

/// Whether `output` can be written, checked before the work that produces it (a long run, a
/// recovery) so a mistyped path costs nothing: an empty path, a folder or device in the way (links
/// followed; a link into /dev or /proc refused), a missing folder, or the very file of one of
/// `inputs` (which the output would destroy) is an error naming the path.
Status check_output_path(const std::filesystem::path& output, std::span<const std::filesystem::path> inputs = {});
/// The same for an output that is a folder of files, made with its missing parents when written:
/// a file in its place (the error says `what` the folder is for), or a nearest existing folder this
/// process cannot write in, is an error.
Status check_output_folder(const std::filesystem::path& output, const std::string& what);
/// Whether two paths name one file: the same as written (made absolute and normal, so a file not yet
/// made counts), or one existing file (hard links, symbolic links and `..` included).
bool names_one_file(const std::filesystem::path& a, const std::filesystem::path& b);
/// The same for several outputs of one command, which must also differ from each other (the last
/// written would replace the others). Empty paths are outputs not asked for and are skipped.
Status check_output_paths(std::span<const std::filesystem::path> outputs, std::span<const std::filesystem::path> inputs = {});

/// Flushes standard output and reports a failed write (a full disk, a closed pipe) as an error.
Status flush_standard_output();

}  // namespace resecto
