// rec recover and rec export.
#include "recordings/recover.h"

#include <cstdio>
#include <string>
#include <string_view>

#include "recordings/byte_io.h"
#include "recordings/recording_writer.h"
#include "rtcore/base/atomic_file.h"
#include "rtcore/base/units.h"
#include "rtcore/mesh/mesh_io.h"

namespace resecto::rec {
namespace {

/// The shared atomic writer (rtcore/base/atomic_file.h) for a byte buffer: it refuses a folder or
/// device in the way and leaves no temporary behind on failure.
Status write_bytes_atomically(const std::filesystem::path& out, std::span<const std::uint8_t> bytes) {
  return write_file_atomically(out, std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size()));
}

}  // namespace

namespace {

/// Writes the recovered file's bytes to `write` a chunk at a time, so a recovery holds one chunk of
/// the recording, not the whole file twice.
template <class Write>
Status write_recovered(const Recording& recording, RecoverReport& report, Write write) {
  report = {};
  std::vector<std::uint8_t> out(std::begin(kFileSignature), std::end(kFileSignature));
  std::uint64_t written = 0;
  auto flush = [&]() -> Status {
    Status status = write(std::span<const std::uint8_t>(out));
    written += out.size();
    out.clear();
    return status;
  };
  std::vector<IndexEntry> index;
  auto add = [&](ChunkType type, std::span<const std::uint8_t> payload, std::uint64_t first_tick) -> Status {
    const auto sequence = static_cast<std::uint32_t>(index.size());
    index.push_back({written + out.size(), static_cast<std::uint16_t>(type), sequence, first_tick, static_cast<std::uint32_t>(payload.size())});
    append_chunk(out, type, sequence, payload);
    ++report.chunks_kept;
    return flush();
  };
  for (const ChunkLocation& chunk : recording.chunks()) {
    if (chunk.type == static_cast<std::uint16_t>(ChunkType::kIndex) || chunk.type == static_cast<std::uint16_t>(ChunkType::kSummary)) continue;
    const Result<std::vector<std::uint8_t>> payload = recording.payload(chunk);
    if (!payload) return Error{payload.error()};
    if (Status added = add(static_cast<ChunkType>(chunk.type), *payload, first_tick_of(chunk.type, *payload)); !added) return added;
  }
  nlohmann::ordered_json summary = recording.summary().is_object() ? recording.summary() : nlohmann::ordered_json::object();
  // A recovery of a recovered file keeps the count of what earlier recoveries left out: replay and
  // score judge by it whether the recording is whole.
  summary["recovered"] = {{"chunks_kept", report.chunks_kept},
                          {"damaged_ranges", recording.recovered_damaged_ranges() + recording.damaged().size()},
                          {"replayable_ticks", recording.replayable_ticks()},
                          {"index_was_present", recording.index_present()}};
  const std::string text = summary.dump();
  if (Status added = add(ChunkType::kSummary, std::span(reinterpret_cast<const std::uint8_t*>(text.data()), text.size()), 0); !added) return added;
  append_index_and_trailer(out, written, index, static_cast<std::uint32_t>(index.size()));
  report.damaged_ranges = recording.damaged().size();
  report.replayable_ticks = recording.replayable_ticks();
  return flush();
}

}  // namespace

Result<std::vector<std::uint8_t>> recovered_bytes(const Recording& recording, RecoverReport& report) {
  std::vector<std::uint8_t> bytes;
  const Status made = write_recovered(recording, report, [&](std::span<const std::uint8_t> chunk) -> Status {
    bytes.insert(bytes.end(), chunk.begin(), chunk.end());
    return Ok{};
  });
  if (!made) return Error{made.error()};
  return bytes;
}

Result<RecoverReport> recover(const Recording& recording, const std::filesystem::path& out) {
  RecoverReport report;
  AtomicFile file;
  if (Status opened = file.open(out); !opened) return Error{opened.error()};
  const Status made = write_recovered(recording, report, [&](std::span<const std::uint8_t> chunk) {
    return file.write(std::string_view(reinterpret_cast<const char*>(chunk.data()), chunk.size()));
  });
  if (!made) return Error{made.error()};  // the temporary is removed with `file`
  if (Status committed = file.commit(); !committed) return Error{committed.error()};
  return report;
}

Status export_keyframe(const Recording& recording, std::size_t k, const std::filesystem::path& out) {
  if (k >= recording.keyframes().size()) {
    return Error{recording.name() + ": keyframe " + std::to_string(k) + " does not exist (" + std::to_string(recording.keyframes().size()) + " recorded)"};
  }
  if (lower_extension(out) == ".drc") {
    const Result<std::vector<std::uint8_t>> draco = recording.keyframe_draco(k);
    if (!draco) return Error{draco.error()};
    return write_bytes_atomically(out, *draco);
  }
  Result<SurfaceFrame> frame = recording.decode_keyframe(k);
  if (!frame) return Error{frame.error()};
  TriangleMesh mesh;
  mesh.positions = std::move(frame->positions);
  mesh.triangles = std::move(frame->triangles);
  return write_surface_mesh(out, mesh);
}

Status export_inputs_csv(const Recording& recording, const std::filesystem::path& out) {
  // The edges' units (DESIGN.md): degrees and millimetres, in a procedure file's column order and
  // names, so a recorded hand can be read beside (or turned into) a procedure. 17 digits: a double's
  // every bit of the converted value. Written in blocks: an hour at 960 Hz is half a gigabyte of text.
  AtomicFile file;
  if (Status opened = file.open(out); !opened) return opened;
  std::string text = "tick,time_s,yaw_deg,pitch_deg,roll_deg,insertion_mm,loop_mm,cut,coagulate,tool_present\n";
  constexpr std::size_t kBlockBytes = std::size_t{1} << 20;
  const double tick_s = recording.header().simulation.tick_s();
  char line[512];
  TickReader ticks(recording);
  while (const TickRecord* record = ticks.next()) {
    const TickRecord& t = *record;
    const DeviceJoints& j = t.input.joints;
    std::snprintf(line, sizeof line, "%llu,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%d,%d,%d\n", static_cast<unsigned long long>(t.tick),
                  static_cast<double>(t.tick) * tick_s, units::rad_to_deg(j.yaw_rad), units::rad_to_deg(j.pitch_rad), units::rad_to_deg(j.roll_rad),
                  units::m_to_mm(j.insertion_m), units::m_to_mm(j.loop_travel_m), t.input.cut ? 1 : 0, t.input.coagulate ? 1 : 0,
                  t.input.tool_present ? 1 : 0);
    text += line;
    if (text.size() < kBlockBytes) continue;
    if (Status wrote = file.write(text); !wrote) return wrote;  // the temporary is removed with `file`
    text.clear();
  }
  if (Status wrote = file.write(text); !wrote) return wrote;
  return file.commit();
}

}  // namespace resecto::rec
