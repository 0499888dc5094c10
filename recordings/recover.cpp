// rec recover and rec export.
#include "recordings/recover.h"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <string>

#include "recordings/byte_io.h"
#include "recordings/recording_writer.h"
#include "rtcore/mesh/mesh_io.h"

namespace resecto::rec {
namespace {

/// Writes `bytes` to a temporary beside `out`, then renames it over `out`.
Status write_file_atomically(const std::filesystem::path& out, std::span<const std::uint8_t> bytes) {
  const std::filesystem::path temporary = out.string() + ".tmp";
  {
    std::ofstream file(temporary, std::ios::binary | std::ios::trunc);
    if (!file) return Error{temporary.string() + ": cannot create"};
    file.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
    if (!file.flush()) return Error{temporary.string() + ": write failed"};
  }
  std::error_code error;
  std::filesystem::rename(temporary, out, error);
  if (error) return Error{out.string() + ": cannot rename the temporary file: " + error.message()};
  return Ok{};
}

}  // namespace

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

Result<RecoverReport> recover(const Recording& recording, const std::filesystem::path& out) {
  const std::filesystem::path temporary = out.string() + ".tmp";
  RecordingWriter writer;
  if (Status opened = writer.open(temporary); !opened) return Error{opened.error()};
  RecoverReport report;
  for (const ChunkLocation& chunk : recording.chunks()) {
    if (chunk.type == static_cast<std::uint16_t>(ChunkType::kIndex) || chunk.type == static_cast<std::uint16_t>(ChunkType::kSummary)) continue;
    const std::span<const std::uint8_t> payload = recording.payload(chunk);
    writer.add_chunk(static_cast<ChunkType>(chunk.type), payload, first_tick_of(chunk.type, payload));
    ++report.chunks_kept;
  }
  nlohmann::ordered_json summary = recording.summary().is_object() ? recording.summary() : nlohmann::ordered_json::object();
  summary["recovered"] = {{"chunks_kept", report.chunks_kept},
                          {"damaged_ranges", recording.damaged().size()},
                          {"replayable_ticks", recording.replayable_ticks()},
                          {"index_was_present", recording.index_present()}};
  const std::string text = summary.dump();
  writer.add_chunk(ChunkType::kSummary, std::span(reinterpret_cast<const std::uint8_t*>(text.data()), text.size()));
  ++report.chunks_kept;
  if (Status closed = writer.close(); !closed) return Error{closed.error()};
  std::error_code error;
  std::filesystem::rename(temporary, out, error);
  if (error) return Error{out.string() + ": cannot rename the temporary file: " + error.message()};
  report.damaged_ranges = recording.damaged().size();
  report.replayable_ticks = recording.replayable_ticks();
  return report;
}

Status export_keyframe(const Recording& recording, std::size_t k, const std::filesystem::path& out) {
  if (k >= recording.keyframes().size()) {
    return Error{"keyframe " + std::to_string(k) + " does not exist (" + std::to_string(recording.keyframes().size()) + " recorded)"};
  }
  if (out.extension() == ".drc") return write_file_atomically(out, recording.keyframe_draco(k));
  Result<SurfaceFrame> frame = recording.decode_keyframe(k);
  if (!frame) return Error{frame.error()};
  TriangleMesh mesh;
  mesh.positions = std::move(frame->positions);
  mesh.triangles = std::move(frame->triangles);
  return write_surface_mesh(out, mesh);
}

Status export_inputs_csv(const Recording& recording, const std::filesystem::path& out) {
  std::string text = "tick,time_s,yaw_rad,pitch_rad,roll_rad,insertion_m,loop_travel_m,cut,coagulate,tool_present\n";
  const double tick_s = recording.header().simulation.tick_s();
  char line[512];
  for (const TickRecord& t : recording.ticks()) {
    const DeviceJoints& j = t.input.joints;
    std::snprintf(line, sizeof line, "%llu,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%d,%d,%d\n", static_cast<unsigned long long>(t.tick),
                  static_cast<double>(t.tick) * tick_s, j.yaw_rad, j.pitch_rad, j.roll_rad, j.insertion_m, j.loop_travel_m, t.input.cut ? 1 : 0,
                  t.input.coagulate ? 1 : 0, t.input.tool_present ? 1 : 0);
    text += line;
  }
  return write_file_atomically(out, std::span(reinterpret_cast<const std::uint8_t*>(text.data()), text.size()));
}

}  // namespace resecto::rec
