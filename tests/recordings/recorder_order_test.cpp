// The order the recorder writes its chunks in: a killed run leaves whatever prefix of the file was
// flushed, so every prefix must hold the inputs (ticks, and the commands they apply) of every hash
// it holds. A batch run makes the core outpace the recorder's thread, where the order is at risk.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <unistd.h>
#include <vector>

#include "recordings/recording_reader.h"
#include "tests/recordings/short_recording.h"

namespace resecto::rec {
namespace {

TEST(RecorderChunkOrder, EveryPrefixOfTheFileHoldsTheInputsOfItsHashesAndTheCommandsOfItsTicks) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / ("resecto_rec_order_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const testing::LiveRun live = testing::record_short(dir / "long.rsrec", 3000);
  std::filesystem::remove_all(dir);
  Result<Recording> recording = Recording::from_bytes(live.file);
  ASSERT_TRUE(recording) << recording.error();
  ASSERT_EQ(recording->steps().size(), live.hashes.size());

  std::optional<std::uint64_t> last_tick_written;
  std::vector<ParameterCommand> commands_written;
  std::size_t steps_chunks = 0;
  for (const ChunkLocation& chunk : recording->chunks()) {
    const std::vector<std::uint8_t> payload = recording->payload(chunk).value();
    if (chunk.type == static_cast<std::uint16_t>(ChunkType::kCommands)) {
      Result<std::vector<ParameterCommand>> block = decode_command_block(payload);
      ASSERT_TRUE(block) << block.error();
      commands_written.insert(commands_written.end(), block->begin(), block->end());
    } else if (chunk.type == static_cast<std::uint16_t>(ChunkType::kTicks)) {
      Result<std::vector<TickRecord>> block = decode_tick_block(payload);
      ASSERT_TRUE(block) << block.error();
      last_tick_written = block->back().tick;
      for (const ParameterCommand& c : live.commands) {
        if (c.apply_tick > static_cast<std::int64_t>(*last_tick_written)) continue;
        EXPECT_TRUE(std::any_of(commands_written.begin(), commands_written.end(), [&](const ParameterCommand& w) { return w.apply_tick == c.apply_tick; }))
            << "the ticks chunk at byte " << chunk.offset << " reaches tick " << *last_tick_written << " before the command for tick "
            << c.apply_tick << " is written";
      }
    } else if (chunk.type == static_cast<std::uint16_t>(ChunkType::kSteps)) {
      Result<std::vector<StepRecord>> block = decode_step_block(payload);
      ASSERT_TRUE(block) << block.error();
      ++steps_chunks;
      ASSERT_TRUE(last_tick_written) << "the steps chunk at byte " << chunk.offset << " comes before any ticks chunk";
      EXPECT_LE(block->back().tick, *last_tick_written)
          << "the steps chunk at byte " << chunk.offset << " holds the hash of tick " << block->back().tick << " while the ticks before it end at "
          << *last_tick_written;
    }
  }
  EXPECT_GT(steps_chunks, 20u);
}

}  // namespace
}  // namespace resecto::rec
