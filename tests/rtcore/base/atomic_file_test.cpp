// The one output writer: a target appears whole or not at all, and only regular files are replaced.
#include <gtest/gtest.h>

#include <sys/stat.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <span>
#include <sstream>
#include <string>
#include <vector>

#include "rtcore/base/atomic_file.h"
#include "rtcore/base/checked_number.h"
#include "rtcore/base/text_file.h"

namespace resecto {
namespace {

std::filesystem::path scratch(const std::string& name) {
  const auto dir = std::filesystem::temp_directory_path() / ("resecto_atomic_file_" + std::to_string(::getpid())) / name;
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

std::string contents(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

std::size_t entries(const std::filesystem::path& dir) {
  return static_cast<std::size_t>(std::distance(std::filesystem::directory_iterator(dir), std::filesystem::directory_iterator()));
}

TEST(AtomicFile, ReplacesARegularFileAndKeepsItsPermissions) {
  const auto dir = scratch("replace");
  const auto target = dir / "out.txt";
  ASSERT_TRUE(write_file_atomically(target, "old\n").ok());
  std::filesystem::permissions(target, std::filesystem::perms::owner_read | std::filesystem::perms::owner_write |
                                           std::filesystem::perms::group_read);
  ASSERT_TRUE(write_file_atomically(target, "new\n").ok());
  EXPECT_EQ(contents(target), "new\n");
  struct stat s {};
  ASSERT_EQ(::stat(target.c_str(), &s), 0);
  EXPECT_EQ(s.st_mode & 0777, 0640u);
  EXPECT_EQ(entries(dir), 1u);
}

TEST(AtomicFile, NothingAppearsUntilCommitAndAnUncommittedFileLeavesNothing) {
  const auto dir = scratch("uncommitted");
  const auto target = dir / "out.txt";
  ASSERT_TRUE(write_file_atomically(target, "good\n").ok());
  {
    AtomicFile file;
    ASSERT_TRUE(file.open(target).ok());
    ASSERT_TRUE(file.write("half of a new").ok());
    EXPECT_EQ(contents(target), "good\n");
    EXPECT_EQ(entries(dir), 2u);  // the target and the temporary beside it
  }
  EXPECT_EQ(contents(target), "good\n");
  EXPECT_EQ(entries(dir), 1u);
}

TEST(OutputPath, IsCheckedBeforeTheWorkThatWouldWriteIt) {
  const auto dir = scratch("check");
  ASSERT_TRUE(write_file_atomically(dir / "input.rsrec", "precious\n").ok());
  std::filesystem::create_directories(dir / "sub");
  std::filesystem::create_hard_link(dir / "input.rsrec", dir / "linked.rsrec");
  const std::filesystem::path input = dir / "input.rsrec";
  const std::span<const std::filesystem::path> inputs(&input, 1);
  EXPECT_TRUE(check_output_path(dir / "new.rsrec", inputs).ok());
  EXPECT_TRUE(check_output_path(dir / "sub" / "..", inputs).error().find("names a folder") != std::string::npos);
  // The input under another spelling, or a hard link to it: writing would destroy it.
  for (const std::filesystem::path& same : {dir / "sub" / ".." / "input.rsrec", dir / "linked.rsrec"}) {
    const Status status = check_output_path(same, inputs);
    ASSERT_FALSE(status.ok()) << same;
    EXPECT_NE(status.error().find("is the input"), std::string::npos) << status.error();
  }
  EXPECT_NE(check_output_path("/dev/null").error().find("is not a regular file"), std::string::npos);
  EXPECT_NE(check_output_path(dir / "sub").error().find("is a folder"), std::string::npos);
  EXPECT_NE(check_output_path(dir / "no" / "report.json").error().find("does not exist"), std::string::npos);
  EXPECT_NE(check_output_path(dir / "input.rsrec" / "report.json").error().find("is not a folder"), std::string::npos);
  // A folder whose permission bits let root (and so access()) in, but that takes no new file.
  const Status proc = check_output_path("/proc/report.json");
  ASSERT_FALSE(proc.ok());
  EXPECT_NE(proc.error().find("cannot create a file in its folder /proc"), std::string::npos) << proc.error();
  EXPECT_EQ(entries(dir), 3u) << "the probe file was left behind";  // input.rsrec, linked.rsrec, sub
  // Two outputs of one command on one path, even one not yet written; outputs not asked for are empty.
  const std::vector<std::filesystem::path> outputs{dir / "a.json", "", dir / "sub" / ".." / "a.json"};
  const Status twice = check_output_paths(outputs);
  ASSERT_FALSE(twice.ok());
  EXPECT_NE(twice.error().find("given for two outputs"), std::string::npos) << twice.error();
  EXPECT_TRUE(check_output_paths(std::vector<std::filesystem::path>{dir / "a.json", "", dir / "b.json"}).ok());
  EXPECT_EQ(contents(dir / "input.rsrec"), "precious\n");
}

TEST(AtomicFile, RefusesFoldersDevicesAndMissingFolders) {
  const auto dir = scratch("refuse");
  std::filesystem::create_directories(dir / "folder.json");
  Status folder = write_file_atomically(dir / "folder.json", "x");
  ASSERT_FALSE(folder.ok());
  EXPECT_NE(folder.error().find("is a folder; not replaced"), std::string::npos) << folder.error();
  Status device = write_file_atomically("/dev/null", "x");
  ASSERT_FALSE(device.ok());
  EXPECT_NE(device.error().find("/dev/null: is not a regular file"), std::string::npos) << device.error();
  Status missing = write_file_atomically(dir / "no" / "such" / "folder.txt", "x");
  ASSERT_FALSE(missing.ok());
  EXPECT_NE(missing.error().find("cannot create a file in its folder: No such file or directory"), std::string::npos) << missing.error();
  EXPECT_EQ(entries(dir), 1u);
}

TEST(AtomicFile, WritesThroughALinkAndRefusesLinksIntoDevOrProc) {
  const auto dir = scratch("links");
  ASSERT_TRUE(write_file_atomically(dir / "target.json", "old\n").ok());
  std::filesystem::create_directories(dir / "sub");
  std::filesystem::create_symlink("../target.json", dir / "sub" / "latest.json");  // relative to its own folder
  std::filesystem::create_symlink(dir / "sub" / "latest.json", dir / "chain.json");
  ASSERT_TRUE(check_output_path(dir / "chain.json").ok());
  ASSERT_TRUE(write_file_atomically(dir / "chain.json", "new\n").ok());
  // Both links are still links; the file they name holds the new text, with no temporary left.
  EXPECT_TRUE(std::filesystem::is_symlink(dir / "chain.json"));
  EXPECT_TRUE(std::filesystem::is_symlink(dir / "sub" / "latest.json"));
  EXPECT_EQ(contents(dir / "target.json"), "new\n");
  EXPECT_EQ(entries(dir), 3u);  // target.json, sub, chain.json
  // A dangling link: the file it names is created.
  std::filesystem::create_symlink("made.json", dir / "dangling.json");
  ASSERT_TRUE(write_file_atomically(dir / "dangling.json", "made\n").ok());
  EXPECT_TRUE(std::filesystem::is_symlink(dir / "dangling.json"));
  EXPECT_EQ(contents(dir / "made.json"), "made\n");
  // /dev/stdout is a link to /proc/self/fd/1: renaming over it would remove the system's link for
  // every process, so it is refused before any work, as is a user's link to it.
  std::filesystem::create_symlink("/proc/self/fd/1", dir / "out.json");
  for (const std::filesystem::path& system : {std::filesystem::path("/dev/stdout"), dir / "out.json"}) {
    const Status checked = check_output_path(system);
    ASSERT_FALSE(checked.ok()) << system;
    EXPECT_NE(checked.error().find("is a link to a device or an open file"), std::string::npos) << checked.error();
    EXPECT_FALSE(write_file_atomically(system, "x").ok()) << system;
  }
  EXPECT_TRUE(std::filesystem::is_symlink("/dev/stdout"));
  EXPECT_TRUE(std::filesystem::is_symlink(dir / "out.json"));
}

TEST(AtomicFile, AFailedOpenKeepsItsReasonThroughWriteAndCommit) {
  // A full disk is tested end to end on a real full tmpfs (tests/console/hostile_input_test.cpp);
  // here: the first failure is the one every later call reports.
  const auto dir = scratch("sticky");
  AtomicFile file;
  ASSERT_FALSE(file.open(dir / "missing" / "x.txt").ok());
  Status write = file.write("x");
  ASSERT_FALSE(write.ok());
  EXPECT_NE(write.error().find("cannot create a file in its folder"), std::string::npos) << write.error();
  Status commit = file.commit();
  ASSERT_FALSE(commit.ok());
  EXPECT_EQ(commit.error(), write.error());
}

TEST(TextFile, RefusesDevicesFoldersAndFilesOverTheCap) {
  const auto dir = scratch("text");
  EXPECT_NE(read_text_file("/dev/urandom").error().find("not a regular file"), std::string::npos);
  EXPECT_NE(read_text_file(dir).error().find("is a folder, not a file"), std::string::npos);
  EXPECT_NE(read_text_file(dir / "missing.txt").error().find("no such file"), std::string::npos);
  ASSERT_TRUE(write_file_atomically(dir / "big.txt", std::string(100, 'x')).ok());
  EXPECT_NE(read_text_file(dir / "big.txt", "", 99).error().find("100 bytes, more than the 99-byte limit"), std::string::npos);
  EXPECT_EQ(read_text_file(dir / "big.txt", "", 100).value().size(), 100u);
}

TEST(CheckedNumber, NanIsNeverInRangeAndValuesPrintExactly) {
  EXPECT_FALSE(in_closed_range(std::nan(""), 0.0, 1.0));
  EXPECT_EQ(range_problem("x", 230.0001, 0.0, 230.0).value(), "x 230.0001 is outside [0, 230]");
  EXPECT_EQ(range_problem("x", std::nan(""), 0.0, 230.0).value(), "x is not a finite number (nan)");
  EXPECT_FALSE(range_problem("x", 230.0, 0.0, 230.0));
  EXPECT_FALSE(parse_finite("nan"));
  EXPECT_FALSE(parse_finite("1e309"));
  EXPECT_FALSE(parse_finite("1.5x"));
  EXPECT_EQ(parse_finite("+2.5").value(), 2.5);
  // Too small for a double is still a number (audit 29, F12: it was called "not a finite number"):
  // its nearest double, for the range check to name.
  EXPECT_EQ(parse_finite("1e-400").value(), 0.0);
  EXPECT_EQ(parse_finite("-1e-400").value(), 0.0);
  EXPECT_GT(parse_finite("4e-320").value(), 0.0);  // subnormal
  EXPECT_FALSE(parse_finite("-1e309"));
  // Audit 6, B: what a refused word is not, for the message.
  for (const char* word : {"0x1p3", "1.0mm", "1,5", "", "+", "--1", "1e", "\xEF\xBC\x91"})
    EXPECT_STREQ(not_finite_kind(word), "not a number") << word;
  for (const char* word : {"nan", "-inf", "+inf", "infinity", "1e999", "-1e309"})
    EXPECT_STREQ(not_finite_kind(word), "not a finite number") << word;
}

}  // namespace
}  // namespace resecto
