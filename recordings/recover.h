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

/// A complete recording made of every intact chunk of `recording` except its old index and summary,
/// renumbered, then a summary (the original's if it had one, noting the recovery), a new index and
/// the trailer. An error when a chunk can no longer be read (the file changed since it was opened).
Result<std::vector<std::uint8_t>> recovered_bytes(const Recording& recording, RecoverReport& report);

/// The same file written to `out` a chunk at a time (through a temporary file, renamed).
Result<RecoverReport> recover(const Recording& recording, const std::filesystem::path& out);

/// Writes keyframe `k`: `.drc` as stored (Draco's own tools read it), or `.ply`, `.obj`, `.off`,
/// `.stl` (millimetres, as `resecto mesh` writes) through the mesh writer.
Status export_keyframe(const Recording& recording, std::size_t k, const std::filesystem::path& out);

/// Writes the per-tick inputs as CSV: tick,time_s,yaw_rad,pitch_rad,roll_rad,insertion_m,
/// loop_travel_m,cut,coagulate,tool_present (17 significant digits: the values read back exactly).
Status export_inputs_csv(const Recording& recording, const std::filesystem::path& out);

}  // namespace resecto::rec
