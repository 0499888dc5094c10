// The recording writer replaces a recording only once the new one is closed: a failed or killed
// run leaves the old file whole and the new one, as far as it got, in TARGET.partial.
#include <gtest/gtest.h>

#include <csignal>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include <sys/resource.h>

#include "recordings/recording_writer.h"

namespace resecto::rec {
namespace {

std::filesystem::path fresh_folder(const std::string& name) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / ("resecto_" + name);
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

std::string read_all(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

void write_all(const std::filesystem::path& path, const std::string& text) { std::ofstream(path, std::ios::binary) << text; }

TEST(RecordingWriter, TheOldRecordingStaysUntilTheNewOneIsClosed) {
  const std::filesystem::path dir = fresh_folder("writer_replace");
  const std::filesystem::path target = dir / "old.rsrec";
  write_all(target, "the old recording");
  RecordingWriter writer;
  ASSERT_TRUE(writer.open(target));
  EXPECT_EQ(writer.partial_path(), target.string() + ".partial");
  const std::vector<std::uint8_t> payload(1000, 7);
  writer.add_chunk(ChunkType::kTicks, payload);
  ASSERT_TRUE(writer.flush());
  // Mid-run: the chunks are on disk beside the target, the target is untouched.
  EXPECT_EQ(read_all(target), "the old recording");
  EXPECT_GT(std::filesystem::file_size(writer.partial_path()), payload.size());
  ASSERT_TRUE(writer.close());
  EXPECT_FALSE(std::filesystem::exists(writer.partial_path()));
  const std::string written = read_all(target);
  ASSERT_GT(written.size(), sizeof kFileSignature);
  EXPECT_TRUE(std::equal(std::begin(kFileSignature), std::end(kFileSignature), written.begin()));
}

TEST(RecordingWriter, AFailedWriteLeavesTheOldRecordingAndSaysWhereTheNewOneIs) {
  const std::filesystem::path dir = fresh_folder("writer_full");
  const std::filesystem::path target = dir / "old.rsrec";
  write_all(target, "the old recording");
  // A disk that fills mid-run, as a file size limit: writes past 16 KiB fail with EFBIG.
  rlimit saved{};
  ASSERT_EQ(::getrlimit(RLIMIT_FSIZE, &saved), 0);
  rlimit limited = saved;
  limited.rlim_cur = 16 * 1024;
  const auto old_handler = std::signal(SIGXFSZ, SIG_IGN);
  ASSERT_EQ(::setrlimit(RLIMIT_FSIZE, &limited), 0);
  RecordingWriter writer;
  const Status opened = writer.open(target);
  writer.add_chunk(ChunkType::kTicks, std::vector<std::uint8_t>(8 * 1024, 1));
  const Status first = writer.flush();
  writer.add_chunk(ChunkType::kTicks, std::vector<std::uint8_t>(64 * 1024, 2));
  const Status second = writer.flush();
  const Status closed = writer.close();
  ::setrlimit(RLIMIT_FSIZE, &saved);
  std::signal(SIGXFSZ, old_handler);

  EXPECT_TRUE(opened);
  EXPECT_TRUE(first);
  EXPECT_FALSE(second);
  ASSERT_FALSE(closed);
  EXPECT_EQ(read_all(target), "the old recording");
  ASSERT_TRUE(std::filesystem::exists(writer.partial_path()));
  EXPECT_NE(closed.error().find(target.string() + " was left as it was: the recording made is in " + writer.partial_path() +
                                " (`resecto rec recover` mends it)"),
            std::string::npos)
      << closed.error();
  EXPECT_NE(closed.error().find("write failed"), std::string::npos) << closed.error();
}

TEST(RecordingWriter, ALinkKeepsPointingAtTheRecordingItNames) {
  const std::filesystem::path dir = fresh_folder("writer_link");
  write_all(dir / "real.rsrec", "the old recording");
  std::filesystem::create_symlink("real.rsrec", dir / "latest.rsrec");
  RecordingWriter writer;
  ASSERT_TRUE(writer.open(dir / "latest.rsrec"));
  EXPECT_EQ(writer.partial_path(), (dir / "real.rsrec").string() + ".partial");
  ASSERT_TRUE(writer.close());
  EXPECT_TRUE(std::filesystem::is_symlink(dir / "latest.rsrec"));
  EXPECT_NE(read_all(dir / "real.rsrec"), "the old recording");
}

}  // namespace
}  // namespace resecto::rec
