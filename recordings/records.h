// What the core hands the recorder, one record per tick and one per collision step, and the chunk
// payloads they are packed into. Blocks are column-major (one column per field, each value's bits
// minus the previous value's, then split into byte planes) and deflated: a slowly changing double
// then costs a few bytes, and the doubles come back bit-exact, which replay needs.
#pragma once

#include <cstdint>
#include <span>
#include <type_traits>
#include <vector>

#include "rtcore/base/result.h"
#include "rtcore/core/simulation.h"
#include "rtcore/core/tick_input.h"

namespace resecto::rec {

/// The input the core latched at `tick`.
struct TickRecord {
  std::uint64_t tick = 0;
  TickInput input;
};

/// A collision step's outcome: what replay verifies (the hash) and what browsing shows.
struct StepRecord {
  std::uint64_t tick = 0;
  std::uint64_t state_hash = 0;
  ToolPoses tool;
  ProcedureMetrics metrics;
};

/// ProcedureMetrics is recorded as one word per field in declaration order (for_each_metric; names in
/// recordings/README.md).
inline constexpr std::uint32_t kMetricWords = static_cast<std::uint32_t>(metric_field_count());

/// Payload of a kTicks chunk: consecutive ticks (`ticks[i].tick == ticks[0].tick + i`).
/// The first tick a chunk's payload covers (ticks, steps, keyframes, commands), 0 for others: what the
/// recorder's index gives for it.
std::uint64_t first_tick_of(std::uint16_t type, std::span<const std::uint8_t> payload);

void encode_tick_block(std::span<const TickRecord> ticks, std::vector<std::uint8_t>& payload);
Result<std::vector<TickRecord>> decode_tick_block(std::span<const std::uint8_t> payload);

/// Payload of a kSteps chunk; `metric_words` is the header's (older files may have fewer fields).
void encode_step_block(std::span<const StepRecord> steps, std::vector<std::uint8_t>& payload);
Result<std::vector<StepRecord>> decode_step_block(std::span<const std::uint8_t> payload);

/// Payload of a kCommands chunk.
void encode_command_block(std::span<const ParameterCommand> commands, std::vector<std::uint8_t>& payload);
Result<std::vector<ParameterCommand>> decode_command_block(std::span<const std::uint8_t> payload);

/// Payload of a kKeyframe chunk: the step it shows, its topology, and the Draco bytes.
struct KeyframeRecord {
  std::uint64_t tick = 0;
  std::uint64_t topology_version = 0;
  bool topology_changed = false;  ///< connectivity differs from the previous keyframe's
  bool has_node_ids = false;      ///< the Draco mesh carries the node-id attribute
  std::uint32_t vertex_count = 0;
  std::uint32_t triangle_count = 0;
  std::span<const std::uint8_t> draco;  ///< into the payload it was parsed from
};
void encode_keyframe_payload(const KeyframeRecord& keyframe, std::vector<std::uint8_t>& payload);
Result<KeyframeRecord> decode_keyframe_payload(std::span<const std::uint8_t> payload);

}  // namespace resecto::rec
