// Recovery and export: rebuilding a complete recording from the intact chunks of a damaged or cut
// one, and writing a keyframe or the inputs out in formats other programs read.
#pragma once

#include <cstdint>
#include <filesystem>

#include "recordings/recording_reader.h"
#include "rtcore/base/result.h"

namespace resecto::rec {

/// What recover() kept.
struct RecoverReport {
  std::uint64_t chunks_kept = 0;
  std::uint64_t damaged_ranges = 0;
  std::uint64_t replayable_ticks = 0;
};

/// Writes `out` (to a temporary file, then renamed) with every intact chunk of `recording` except
/// its old index, renumbered, then a summary (the original's if it had one, noting the recovery)
/// and a new index and trailer.
Result<RecoverReport> recover(const Recording& recording, const std::filesystem::path& out);

/// Writes keyframe `k`: `.drc` as stored (Draco's own tools read it), or `.ply`, `.obj`, `.off`,
/// `.stl` (millimetres, as `resecto mesh` writes) through the mesh writer.
Status export_keyframe(const Recording& recording, std::size_t k, const std::filesystem::path& out);

/// Writes the per-tick inputs as CSV: tick,time_s,yaw_rad,pitch_rad,roll_rad,insertion_m,
/// loop_travel_m,cut,coagulate,tool_present (17 significant digits: the values read back exactly).
Status export_inputs_csv(const Recording& recording, const std::filesystem::path& out);

/// The first tick a chunk's payload covers (ticks, steps, keyframes, commands), 0 for others.
std::uint64_t first_tick_of(std::uint16_t type, std::span<const std::uint8_t> payload);

}  // namespace resecto::rec
