// A recording read from its file where it lies: the scan in windows finds what a scan of the bytes
// in memory finds, whatever the window's size and wherever the damage falls, and a file changed after
// it was opened gives errors, never its new bytes as the old.
#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "recordings/recording_bytes.h"
#include "recordings/recording_reader.h"
#include "tests/recordings/short_recording.h"

namespace resecto::rec {
namespace {

using testing::short_recording;

class RecordingBytesTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() / ("resecto_recording_bytes_" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }

  std::filesystem::path write(const std::string& name, const std::vector<std::uint8_t>& bytes) const {
    const std::filesystem::path path = dir_ / name;
    std::ofstream(path, std::ios::binary).write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
    return path;
  }

  std::filesystem::path dir_;
};

void expect_same_scan(const ChunkScan& a, const ChunkScan& b, const std::string& what) {
  EXPECT_EQ(a.signature_ok, b.signature_ok) << what;
  EXPECT_EQ(a.trailer_present, b.trailer_present) << what;
  EXPECT_EQ(a.file_bytes, b.file_bytes) << what;
  EXPECT_EQ(a.tail_bytes, b.tail_bytes) << what;
  ASSERT_EQ(a.chunks.size(), b.chunks.size()) << what;
  for (std::size_t c = 0; c < a.chunks.size(); ++c) {
    EXPECT_EQ(a.chunks[c].offset, b.chunks[c].offset) << what << ", chunk " << c;
    EXPECT_EQ(a.chunks[c].type, b.chunks[c].type) << what << ", chunk " << c;
    EXPECT_EQ(a.chunks[c].sequence, b.chunks[c].sequence) << what << ", chunk " << c;
    EXPECT_EQ(a.chunks[c].payload_bytes, b.chunks[c].payload_bytes) << what << ", chunk " << c;
  }
  ASSERT_EQ(a.damaged.size(), b.damaged.size()) << what;
  for (std::size_t d = 0; d < a.damaged.size(); ++d) EXPECT_EQ(describe(a.damaged[d]), describe(b.damaged[d])) << what;
}

TEST_F(RecordingBytesTest, TheScanInWindowsOfAnySizeFindsWhatTheScanInMemoryFinds) {
  const std::vector<std::uint8_t>& intact = short_recording().file;
  const ChunkScan reference = scan_chunks(intact);
  ASSERT_GE(reference.chunks.size(), 10u);
  // Damage of every kind a scan meets: a payload's bit, a frame's bit (the scan resynchronises on the
  // next marker, searched across windows), garbage between chunks, a cut inside a chunk, the trailer lost.
  std::vector<std::pair<std::string, std::vector<std::uint8_t>>> files = {{"intact", intact}};
  const ChunkLocation& middle = reference.chunks[reference.chunks.size() / 2];
  std::vector<std::uint8_t> payload_flipped = intact;
  payload_flipped[middle.payload_offset() + middle.payload_bytes / 2] ^= 0x10;
  files.emplace_back("payload bit", payload_flipped);
  std::vector<std::uint8_t> frame_flipped = intact;
  frame_flipped[middle.offset + 9] ^= 0x01;
  files.emplace_back("frame bit", frame_flipped);
  std::vector<std::uint8_t> garbage = intact;
  garbage.insert(garbage.begin() + static_cast<std::ptrdiff_t>(middle.offset), 5000, std::uint8_t{'C'});
  files.emplace_back("garbage", garbage);
  files.emplace_back("cut", std::vector<std::uint8_t>(intact.begin(), intact.begin() + static_cast<std::ptrdiff_t>(middle.offset + 30)));
  files.emplace_back("no trailer", std::vector<std::uint8_t>(intact.begin(), intact.end() - 3));

  for (const auto& [name, bytes] : files) {
    const ChunkScan in_memory = scan_chunks(bytes);
    if (name != "intact") {
      EXPECT_FALSE(in_memory.damaged.empty() && in_memory.trailer_present) << name;
    }
    const Result<RecordingBytes> file = RecordingBytes::open(write("scan.rsrec", bytes));
    ASSERT_TRUE(file) << file.error();
    for (const std::size_t window : {std::size_t{1}, std::size_t{7}, std::size_t{64}, std::size_t{4096}, ByteWindow::kDefaultBlockBytes}) {
      expect_same_scan(scan_chunks(*file, window), in_memory, name + " in windows of " + std::to_string(window) + " bytes");
    }
  }
}

TEST_F(RecordingBytesTest, ARecordingOpenedFromItsFileReadsAsFromItsBytes) {
  const testing::LiveRun& live = short_recording();
  const Result<Recording> from_file = Recording::open(write("session.rsrec", live.file));
  const Result<Recording> from_bytes = Recording::from_bytes(live.file);
  ASSERT_TRUE(from_file) << from_file.error();
  ASSERT_TRUE(from_bytes) << from_bytes.error();
  EXPECT_EQ(from_file->file_bytes(), live.file.size());
  ASSERT_EQ(from_file->tick_count(), from_bytes->tick_count());
  ASSERT_EQ(from_file->steps().size(), from_bytes->steps().size());
  for (std::size_t i = 0; i < from_file->steps().size(); ++i) EXPECT_EQ(from_file->steps()[i].state_hash, from_bytes->steps()[i].state_hash);
  ASSERT_EQ(from_file->keyframes().size(), from_bytes->keyframes().size());
  ASSERT_FALSE(from_file->keyframes().empty());
  for (std::size_t k = 0; k < from_file->keyframes().size(); ++k) {
    EXPECT_EQ(from_file->keyframe_draco(k).value(), from_bytes->keyframe_draco(k).value()) << "keyframe " << k;
    EXPECT_TRUE(from_file->decode_keyframe(k)) << "keyframe " << k;
  }
}

TEST_F(RecordingBytesTest, AFileChangedAfterItWasOpenedGivesErrorsNotItsNewBytes) {
  const testing::LiveRun& live = short_recording();
  const std::filesystem::path path = write("changing.rsrec", live.file);
  const Result<Recording> r = Recording::open(path);
  ASSERT_TRUE(r) << r.error();
  ASSERT_GE(r->keyframes().size(), 2u);
  const ChunkLocation& first = r->chunks()[r->keyframes().front().chunk];
  const ChunkLocation& last = r->chunks()[r->keyframes().back().chunk];

  // Overwritten in place (another program wrote over it): the chunk's CRC no longer holds.
  {
    std::fstream file(path, std::ios::binary | std::ios::in | std::ios::out);
    file.seekp(static_cast<std::streamoff>(first.payload_offset() + first.payload_bytes / 2));
    file.put('\x5a').put('\xa5');
  }
  const Result<std::vector<std::uint8_t>> overwritten = r->keyframe_draco(0);
  ASSERT_FALSE(overwritten);
  EXPECT_NE(overwritten.error().find("changed since the recording was opened"), std::string::npos) << overwritten.error();
  EXPECT_NE(overwritten.error().find(path.string() + ": keyframe chunk " + std::to_string(first.sequence)), std::string::npos) << overwritten.error();
  EXPECT_FALSE(r->decode_keyframe(0));

  // A collision step's record: its chunk is read again, and checked.
  const ChunkLocation& steps_chunk = r->chunks()[r->steps().front().chunk];
  {
    std::fstream file(path, std::ios::binary | std::ios::in | std::ios::out);
    file.seekp(static_cast<std::streamoff>(steps_chunk.payload_offset() + steps_chunk.payload_bytes / 2));
    file.put('\x5a').put('\xa5');
  }
  StepReader steps(*r);
  const Result<StepRecord> step = steps.at(0);
  ASSERT_FALSE(step);
  EXPECT_NE(step.error().find(path.string() + ": steps chunk " + std::to_string(steps_chunk.sequence)), std::string::npos) << step.error();
  EXPECT_NE(step.error().find("changed since the recording was opened"), std::string::npos) << step.error();

  // Cut shorter: the chunk is no longer there to read.
  std::filesystem::resize_file(path, last.offset + 10);
  const Result<SurfaceFrame> cut = r->decode_keyframe(r->keyframes().size() - 1);
  ASSERT_FALSE(cut);
  EXPECT_NE(cut.error().find("can no longer be read"), std::string::npos) << cut.error();
}

TEST_F(RecordingBytesTest, OnlyARegularFileIsOpened) {
  const Result<RecordingBytes> folder = RecordingBytes::open(dir_);
  ASSERT_FALSE(folder);
  EXPECT_NE(folder.error().find("is a folder"), std::string::npos) << folder.error();
  const Result<RecordingBytes> device = RecordingBytes::open("/dev/zero");
  ASSERT_FALSE(device);
  EXPECT_NE(device.error().find("not a regular file"), std::string::npos) << device.error();
  const Result<RecordingBytes> missing = RecordingBytes::open(dir_ / "missing.rsrec");
  ASSERT_FALSE(missing);
  EXPECT_NE(missing.error().find("no such file"), std::string::npos) << missing.error();
}

}  // namespace
}  // namespace resecto::rec
