// Packing of tick, step, command and keyframe payloads (layouts in recordings/README.md).
#include "recordings/records.h"

#include <cstring>
#include <string>

#include <zlib.h>

#include "recordings/byte_io.h"

namespace resecto::rec {
namespace {

/// Rows of `columns` 64-bit words -> XOR with the previous row, byte planes, deflate.
void put_columns(ByteWriter& w, std::span<const std::uint64_t> words, std::uint32_t rows, std::uint32_t columns) {
  std::vector<std::uint8_t> planes(words.size() * 8);
  const std::size_t n = rows;
  for (std::uint32_t c = 0; c < columns; ++c) {
    std::uint64_t previous = 0;
    for (std::uint32_t r = 0; r < rows; ++r) {
      const std::uint64_t word = words[static_cast<std::size_t>(r) * columns + c];
      const std::uint64_t delta = word ^ previous;
      previous = word;
      for (int b = 0; b < 8; ++b) planes[(static_cast<std::size_t>(c) * 8 + static_cast<std::size_t>(b)) * n + r] = static_cast<std::uint8_t>(delta >> (8 * b));
    }
  }
  uLongf packed_bytes = compressBound(static_cast<uLong>(planes.size()));
  std::vector<std::uint8_t> packed(packed_bytes);
  compress2(packed.data(), &packed_bytes, planes.data(), static_cast<uLong>(planes.size()), 6);
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
      previous ^= delta;
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
  RigidPose pose;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) pose.rotation[c][r] = double_of(in[r * 4 + c]);
    pose.translation[r] = double_of(in[r * 4 + 3]);
  }
  return pose;
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
    std::memcpy(row + 2 + 2 * kPoseWords, &steps[i].metrics, sizeof(ProcedureMetrics));
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
    std::memcpy(static_cast<void*>(&steps[i].metrics), row + 2 + 2 * kPoseWords, sizeof(ProcedureMetrics));
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
  for (ParameterCommand& c : commands) {
    c.apply_tick = r.get<std::int64_t>();
    const auto id = r.get<std::uint8_t>();
    if (id >= kTissueParameterCount) return Error{"commands: unknown parameter " + std::to_string(id)};
    c.id = static_cast<TissueParameter>(id);
    c.value = r.get<double>();
  }
  return commands;
}

void encode_keyframe_payload(const KeyframeRecord& k, std::vector<std::uint8_t>& payload) {
  payload.clear();
  ByteWriter w(payload);
  w.put(k.tick);
  w.put(k.topology_version);
  w.put(static_cast<std::uint8_t>(k.topology_changed ? 1 : 0));
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
  if (!r.ok() || changed > 1) return Error{"keyframe: bad fixed fields"};
  k.topology_changed = changed == 1;
  k.draco = r.get_bytes(r.remaining());
  return k;
}

}  // namespace resecto::rec
