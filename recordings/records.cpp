// Packing of tick, step, command and keyframe payloads (layouts in recordings/README.md).
#include "recordings/records.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <optional>
#include <type_traits>
#include <string>

#include <zlib.h>

#include "recordings/byte_io.h"
#include "recordings/chunk_format.h"

namespace resecto::rec {
namespace {

/// A signed difference with its sign in the low bit, so small steps either way have zero high bytes.
std::uint64_t zigzag(std::uint64_t difference) { return (difference << 1) ^ (0 - (difference >> 63)); }
std::uint64_t unzigzag(std::uint64_t z) { return (z >> 1) ^ (0 - (z & 1)); }

/// Rows of `columns` 64-bit words -> difference from the previous row (as integers: for doubles of
/// one sign and exponent that is proportional to the value's change), zigzagged, split into byte
/// planes, deflated.
void put_columns(ByteWriter& w, std::span<const std::uint64_t> words, std::uint32_t rows, std::uint32_t columns) {
  std::vector<std::uint8_t> planes(words.size() * 8);
  const std::size_t n = rows;
  for (std::uint32_t c = 0; c < columns; ++c) {
    std::uint64_t previous = 0;
    for (std::uint32_t r = 0; r < rows; ++r) {
      const std::uint64_t word = words[static_cast<std::size_t>(r) * columns + c];
      const std::uint64_t delta = zigzag(word - previous);
      previous = word;
      for (int b = 0; b < 8; ++b) planes[(static_cast<std::size_t>(c) * 8 + static_cast<std::size_t>(b)) * n + r] = static_cast<std::uint8_t>(delta >> (8 * b));
    }
  }
  uLongf packed_bytes = compressBound(static_cast<uLong>(planes.size()));
  std::vector<std::uint8_t> packed(packed_bytes);
  compress2(packed.data(), &packed_bytes, planes.data(), static_cast<uLong>(planes.size()), 9);
  w.put(rows);
  w.put(columns);
  w.put(static_cast<std::uint32_t>(packed_bytes));
  w.put_bytes(std::span<const std::uint8_t>(packed.data(), packed_bytes));
}

/// The inverse of put_columns. The row and column counts are checked against what deflate can
/// possibly expand the packed bytes to before anything is allocated.
Result<std::vector<std::uint64_t>> get_columns(ByteReader& r, std::uint32_t expected_columns, std::uint32_t& rows) {
  rows = r.get<std::uint32_t>();
  const std::uint32_t columns = r.get<std::uint32_t>();
  const std::uint32_t packed_bytes = r.get<std::uint32_t>();
  const std::span<const std::uint8_t> packed = r.get_bytes(packed_bytes);
  if (!r.ok()) return Error{"block cut short"};
  if (columns != expected_columns) return Error{"block has " + std::to_string(columns) + " columns, expected " + std::to_string(expected_columns)};
  const std::uint64_t plane_bytes = std::uint64_t{rows} * columns * 8;
  // deflate never expands better than ~1032:1
  if (plane_bytes > std::uint64_t{packed_bytes} * 1032 + 64 || plane_bytes > (std::uint64_t{1} << 30)) return Error{"block sizes are inconsistent"};
  std::vector<std::uint8_t> planes(plane_bytes);
  uLongf out_bytes = static_cast<uLongf>(plane_bytes);
  if (uncompress(planes.data(), &out_bytes, packed.data(), packed_bytes) != Z_OK || out_bytes != plane_bytes) {
    return Error{"block does not inflate"};
  }
  std::vector<std::uint64_t> words(static_cast<std::size_t>(rows) * columns);
  const std::size_t n = rows;
  for (std::uint32_t c = 0; c < columns; ++c) {
    std::uint64_t previous = 0;
    for (std::uint32_t row = 0; row < rows; ++row) {
      std::uint64_t delta = 0;
      for (int b = 0; b < 8; ++b) delta |= std::uint64_t{planes[(static_cast<std::size_t>(c) * 8 + static_cast<std::size_t>(b)) * n + row]} << (8 * b);
      previous += unzigzag(delta);
      words[static_cast<std::size_t>(row) * columns + c] = previous;
    }
  }
  return words;
}

std::uint64_t bits_of(double v) { return std::bit_cast<std::uint64_t>(v); }
double double_of(std::uint64_t w) { return std::bit_cast<double>(w); }

constexpr std::uint32_t kTickColumns = 6;  // yaw, pitch, roll, insertion, loop travel, flags
constexpr std::uint32_t kPoseWords = 12;
constexpr std::uint32_t kStepColumns = 2 + 2 * kPoseWords + kMetricWords;

void put_pose(std::uint64_t* out, const RigidPose& pose) {
  const std::array<double, 12> m = to_row_major_3x4(pose);
  for (std::size_t i = 0; i < 12; ++i) out[i] = bits_of(m[i]);
}

RigidPose get_pose(const std::uint64_t* in) {
  std::array<double, 12> m{};
  for (std::size_t i = 0; i < 12; ++i) m[i] = double_of(in[i]);
  return from_row_major_3x4(m);
}

// The distal margin's word when there is none yet (no cut). Files written before it became an
// optional hold 1e9 there, which reads back as none too.
constexpr double kNoMarginWord = std::numeric_limits<double>::quiet_NaN();
constexpr double kOldNoMarginWord = 1e9;

void put_metrics(std::uint64_t* out, const ProcedureMetrics& metrics) {
  std::size_t w = 0;
  for_each_metric(metrics, [&](const auto& field) {
    using Field = std::decay_t<decltype(field)>;
    if constexpr (std::is_same_v<Field, std::uint64_t>) {
      out[w++] = field;
    } else if constexpr (std::is_same_v<Field, double>) {
      out[w++] = bits_of(field);
    } else {
      out[w++] = bits_of(field.value_or(kNoMarginWord));
    }
  });
}

ProcedureMetrics get_metrics(const std::uint64_t* in) {
  ProcedureMetrics metrics;
  std::size_t w = 0;
  for_each_metric(metrics, [&](auto& field) {
    using Field = std::decay_t<decltype(field)>;
    if constexpr (std::is_same_v<Field, std::uint64_t>) {
      field = in[w++];
    } else if constexpr (std::is_same_v<Field, double>) {
      field = double_of(in[w++]);
    } else {
      const double value = double_of(in[w++]);
      field = std::isnan(value) || value >= kOldNoMarginWord ? std::nullopt : std::optional<double>(value);
    }
  });
  return metrics;
}

}  // namespace

void encode_tick_block(std::span<const TickRecord> ticks, std::vector<std::uint8_t>& payload) {
  payload.clear();
  ByteWriter w(payload);
  w.put(ticks.empty() ? std::uint64_t{0} : ticks.front().tick);
  std::vector<std::uint64_t> words;
  words.reserve(ticks.size() * kTickColumns);
  for (const TickRecord& t : ticks) {
    const DeviceJoints& j = t.input.joints;
    words.insert(words.end(), {bits_of(j.yaw_rad), bits_of(j.pitch_rad), bits_of(j.roll_rad), bits_of(j.insertion_m), bits_of(j.loop_travel_m),
                               std::uint64_t{t.input.cut} | std::uint64_t{t.input.coagulate} << 1 | std::uint64_t{t.input.tool_present} << 2});
  }
  put_columns(w, words, static_cast<std::uint32_t>(ticks.size()), kTickColumns);
}

Result<std::vector<TickRecord>> decode_tick_block(std::span<const std::uint8_t> payload) {
  ByteReader r(payload);
  const std::uint64_t first = r.get<std::uint64_t>();
  std::uint32_t rows = 0;
  Result<std::vector<std::uint64_t>> words = get_columns(r, kTickColumns, rows);
  if (!words) return Error{"ticks: " + words.error()};
  std::vector<TickRecord> ticks(rows);
  for (std::uint32_t i = 0; i < rows; ++i) {
    const std::uint64_t* w = words->data() + static_cast<std::size_t>(i) * kTickColumns;
    TickRecord& t = ticks[i];
    t.tick = first + i;
    t.input.joints = {double_of(w[0]), double_of(w[1]), double_of(w[2]), double_of(w[3]), double_of(w[4])};
    if (w[5] > 7) return Error{"ticks: bad flags at tick " + std::to_string(t.tick)};
    t.input.cut = (w[5] & 1) != 0;
    t.input.coagulate = (w[5] & 2) != 0;
    t.input.tool_present = (w[5] & 4) != 0;
  }
  return ticks;
}

void encode_step_block(std::span<const StepRecord> steps, std::vector<std::uint8_t>& payload) {
  payload.clear();
  ByteWriter w(payload);
  std::vector<std::uint64_t> words(steps.size() * kStepColumns);
  for (std::size_t i = 0; i < steps.size(); ++i) {
    std::uint64_t* row = words.data() + i * kStepColumns;
    row[0] = steps[i].tick;
    row[1] = steps[i].state_hash;
    put_pose(row + 2, steps[i].tool.sheath);
    put_pose(row + 2 + kPoseWords, steps[i].tool.loop);
    put_metrics(row + 2 + 2 * kPoseWords, steps[i].metrics);
  }
  put_columns(w, words, static_cast<std::uint32_t>(steps.size()), kStepColumns);
}

Result<std::vector<StepRecord>> decode_step_block(std::span<const std::uint8_t> payload) {
  ByteReader r(payload);
  std::uint32_t rows = 0;
  Result<std::vector<std::uint64_t>> words = get_columns(r, kStepColumns, rows);
  if (!words) return Error{"steps: " + words.error()};
  std::vector<StepRecord> steps(rows);
  for (std::uint32_t i = 0; i < rows; ++i) {
    const std::uint64_t* row = words->data() + static_cast<std::size_t>(i) * kStepColumns;
    steps[i].tick = row[0];
    steps[i].state_hash = row[1];
    steps[i].tool.sheath = get_pose(row + 2);
    steps[i].tool.loop = get_pose(row + 2 + kPoseWords);
    steps[i].metrics = get_metrics(row + 2 + 2 * kPoseWords);
  }
  return steps;
}

void encode_command_block(std::span<const ParameterCommand> commands, std::vector<std::uint8_t>& payload) {
  payload.clear();
  ByteWriter w(payload);
  w.put(static_cast<std::uint32_t>(commands.size()));
  for (const ParameterCommand& c : commands) {
    w.put(c.apply_tick);
    w.put(static_cast<std::uint8_t>(c.id));
    w.put(c.value);
  }
}

Result<std::vector<ParameterCommand>> decode_command_block(std::span<const std::uint8_t> payload) {
  ByteReader r(payload);
  const std::uint32_t count = r.get<std::uint32_t>();
  if (std::uint64_t{count} * 17 != r.remaining()) return Error{"commands: count and length disagree"};
  std::vector<ParameterCommand> commands(count);
  TissueParameters check;  // the console's own range check, reused
  for (ParameterCommand& c : commands) {
    c.apply_tick = r.get<std::int64_t>();
    const auto id = r.get<std::uint8_t>();
    if (id >= kTissueParameterCount) return Error{"commands: unknown parameter " + std::to_string(id)};
    c.id = static_cast<TissueParameter>(id);
    c.value = r.get<double>();
    // The core applies a command as already validated (ParameterCommand::value): one the console
    // could never have sent (NaN, out of its range) marks a file made by something else.
    if (Status valid = check.set(c.id, c.value); !valid) return Error{"commands: tick " + std::to_string(c.apply_tick) + ": " + valid.error()};
  }
  return commands;
}

void encode_keyframe_payload(const KeyframeRecord& k, std::vector<std::uint8_t>& payload) {
  payload.clear();
  ByteWriter w(payload);
  w.put(k.tick);
  w.put(k.topology_version);
  w.put(static_cast<std::uint8_t>((k.topology_changed ? 1 : 0) | (k.has_node_ids ? 2 : 0)));
  w.put(k.vertex_count);
  w.put(k.triangle_count);
  w.put_bytes(k.draco);
}

Result<KeyframeRecord> decode_keyframe_payload(std::span<const std::uint8_t> payload) {
  ByteReader r(payload);
  KeyframeRecord k;
  k.tick = r.get<std::uint64_t>();
  k.topology_version = r.get<std::uint64_t>();
  const auto changed = r.get<std::uint8_t>();
  k.vertex_count = r.get<std::uint32_t>();
  k.triangle_count = r.get<std::uint32_t>();
  if (!r.ok() || changed > 3) return Error{"keyframe: bad fixed fields"};
  k.topology_changed = (changed & 1) != 0;
  k.has_node_ids = (changed & 2) != 0;
  k.draco = r.get_bytes(r.remaining());
  return k;
}

std::uint64_t first_tick_of(std::uint16_t type, std::span<const std::uint8_t> payload) {
  switch (static_cast<ChunkType>(type)) {
    case ChunkType::kTicks:
    case ChunkType::kKeyframe: {
      ByteReader r(payload);
      return r.get<std::uint64_t>();
    }
    case ChunkType::kSteps: {
      Result<std::vector<StepRecord>> steps = decode_step_block(payload);
      return steps && !steps->empty() ? steps->front().tick : 0;
    }
    case ChunkType::kCommands: {
      Result<std::vector<ParameterCommand>> commands = decode_command_block(payload);
      return commands && !commands->empty() ? static_cast<std::uint64_t>(std::max<std::int64_t>(0, commands->front().apply_tick)) : 0;
    }
    default:
      return 0;
  }
}

}  // namespace resecto::rec
