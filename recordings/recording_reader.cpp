// Opening a recording: scan, header, the decoded tick/step/command streams and the keyframe index.
#include "recordings/recording_reader.h"

#include <algorithm>
#include <exception>
#include <filesystem>

#include "recordings/recording_writer.h"
#include "rtcore/base/json_text.h"
#include "rtcore/base/text_file.h"

namespace resecto::rec {

Result<Recording> Recording::open(const std::filesystem::path& path) {
  // Only a regular file, read once to its size: a device or a pipe named as a recording would be
  // read for ever (/dev/zero filled the memory).
  std::error_code error;
  if (std::filesystem::is_directory(path, error)) return Error{path.string() + ": is a folder, not a recording"};
  Result<std::vector<std::uint8_t>> bytes = read_regular_file<std::vector<std::uint8_t>>(path, " the recording", kMaxBinaryFileBytes);
  if (!bytes) return Error{bytes.error()};
  return from_bytes(std::move(*bytes), path.string());
}

Result<Recording> Recording::from_bytes(std::vector<std::uint8_t> bytes, std::string name) {
  Recording r;
  r.name_ = name;
  r.bytes_ = std::move(bytes);
  r.scan_ = scan_chunks(r.bytes_);
  if (!r.scan_.signature_ok) return Error{name + ": not a Resecto recording (bad signature)"};
  bool have_header = false;
  for (std::size_t c = 0; c < r.scan_.chunks.size(); ++c) {
    if (have_header && r.scan_.chunks[c].type == static_cast<std::uint16_t>(ChunkType::kHeader)) {
      // A second header starts another recording (two files joined): its ticks would pass for this
      // one's past its end. It and everything after it are left out, and the file is not sound.
      r.content_errors_.push_back("header chunk " + std::to_string(r.scan_.chunks[c].sequence) + " at byte " + std::to_string(r.scan_.chunks[c].offset) +
                                  ": a second header, another recording (two files joined?); it and the " +
                                  std::to_string(r.scan_.chunks.size() - c) + " chunks from it on are left out");
      r.scan_.chunks.resize(c);
      break;
    }
    const ChunkLocation& chunk = r.scan_.chunks[c];
    const std::span<const std::uint8_t> payload = r.payload(chunk);
    const std::string where = std::string(chunk_type_name(chunk.type)) + " chunk " + std::to_string(chunk.sequence) + " at byte " + std::to_string(chunk.offset);
    switch (static_cast<ChunkType>(chunk.type)) {
      case ChunkType::kHeader: {
        Result<SessionHeader> header = header_from_json(std::string_view(reinterpret_cast<const char*>(payload.data()), payload.size()));
        if (!header) return Error{name + ": " + header.error()};
        r.header_ = std::move(*header);
        have_header = true;
        break;
      }
      case ChunkType::kTicks: {
        Result<std::vector<TickRecord>> ticks = decode_tick_block(payload);
        if (!ticks) r.content_errors_.push_back(where + ": " + ticks.error());
        else r.ticks_.insert(r.ticks_.end(), ticks->begin(), ticks->end());
        break;
      }
      case ChunkType::kSteps: {
        Result<std::vector<StepRecord>> steps = decode_step_block(payload);
        if (!steps) r.content_errors_.push_back(where + ": " + steps.error());
        else r.steps_.insert(r.steps_.end(), steps->begin(), steps->end());
        break;
      }
      case ChunkType::kCommands: {
        Result<std::vector<ParameterCommand>> commands = decode_command_block(payload);
        if (!commands) r.content_errors_.push_back(where + ": " + commands.error());
        else r.commands_.insert(r.commands_.end(), commands->begin(), commands->end());
        break;
      }
      case ChunkType::kKeyframe: {
        Result<KeyframeRecord> k = decode_keyframe_payload(payload);
        if (!k) {
          r.content_errors_.push_back(where + ": " + k.error());
          break;
        }
        r.keyframes_.push_back({k->tick, 0.0, k->topology_version, k->topology_changed, k->has_node_ids, k->vertex_count, k->triangle_count,
                                static_cast<std::uint32_t>(k->draco.size()), c});
        break;
      }
      case ChunkType::kSummary:
        try {
          r.summary_ = nlohmann::ordered_json::parse(payload.begin(), payload.end());
        } catch (const std::exception& e) {
          r.content_errors_.push_back(where + ": " + library_free(e.what()));
        }
        break;
      case ChunkType::kIndex:
        if (Result<std::vector<IndexEntry>> index = decode_index(payload); !index) r.content_errors_.push_back(where + ": " + index.error());
        break;
    }
  }
  if (!have_header) return Error{name + ": no intact header chunk (nothing to replay from)"};

  // Sorted by tick; a record seen twice (never written so, but a copied chunk could be) is kept once.
  auto by_tick = [](const auto& a, const auto& b) { return a.tick < b.tick; };
  auto same_tick = [](const auto& a, const auto& b) { return a.tick == b.tick; };
  std::stable_sort(r.ticks_.begin(), r.ticks_.end(), by_tick);
  r.ticks_.erase(std::unique(r.ticks_.begin(), r.ticks_.end(), same_tick), r.ticks_.end());
  std::stable_sort(r.steps_.begin(), r.steps_.end(), by_tick);
  r.steps_.erase(std::unique(r.steps_.begin(), r.steps_.end(), same_tick), r.steps_.end());
  std::stable_sort(r.keyframes_.begin(), r.keyframes_.end(), by_tick);
  r.keyframes_.erase(std::unique(r.keyframes_.begin(), r.keyframes_.end(), same_tick), r.keyframes_.end());
  std::stable_sort(r.commands_.begin(), r.commands_.end(), [](const ParameterCommand& a, const ParameterCommand& b) { return a.apply_tick < b.apply_tick; });
  const double tick_s = r.header_.simulation.tick_s();
  for (KeyframeInfo& k : r.keyframes_) k.time_s = static_cast<double>(k.tick) * tick_s;

  const auto start = static_cast<std::uint64_t>(r.header_.start_tick);
  std::uint64_t next = start;
  for (const TickRecord& t : r.ticks_) {
    if (t.tick < next) continue;
    if (t.tick != next) break;
    ++next;
  }
  r.replayable_ticks_ = next - start;
  return r;
}

std::span<const std::uint8_t> Recording::payload(const ChunkLocation& chunk) const {
  return std::span<const std::uint8_t>(bytes_).subspan(chunk.payload_offset(), chunk.payload_bytes);
}

std::optional<std::size_t> Recording::keyframe_at_time(double time_s) const {
  auto after = std::upper_bound(keyframes_.begin(), keyframes_.end(), time_s, [](double t, const KeyframeInfo& k) { return t < k.time_s; });
  if (after == keyframes_.begin()) return std::nullopt;
  return static_cast<std::size_t>(after - keyframes_.begin() - 1);
}

std::span<const std::uint8_t> Recording::keyframe_draco(std::size_t k) const {
  Result<KeyframeRecord> record = decode_keyframe_payload(payload(scan_.chunks[keyframes_.at(k).chunk]));
  return record ? record->draco : std::span<const std::uint8_t>();
}

std::string Recording::keyframe_place(std::size_t k) const {
  const ChunkLocation& chunk = scan_.chunks[keyframes_[k].chunk];
  return name_ + ": keyframe " + std::to_string(k) + " (chunk " + std::to_string(chunk.sequence) + " at byte " + std::to_string(chunk.offset) + ")";
}

Result<SurfaceFrame> Recording::decode_keyframe(std::size_t k) const {
  if (k >= keyframes_.size()) {
    return Error{name_ + ": keyframe " + std::to_string(k) + " does not exist (" + std::to_string(keyframes_.size()) + " recorded)"};
  }
  Result<SurfaceFrame> frame = rec::decode_keyframe(keyframe_draco(k));
  if (!frame) return Error{keyframe_place(k) + ": " + frame.error()};
  if (frame->positions.size() != keyframes_[k].vertex_count || frame->triangles.size() != keyframes_[k].triangle_count) {
    return Error{keyframe_place(k) + ": decoded " + std::to_string(frame->positions.size()) + " vertices and " +
                 std::to_string(frame->triangles.size()) + " triangles, the chunk says " + std::to_string(keyframes_[k].vertex_count) + " and " +
                 std::to_string(keyframes_[k].triangle_count)};
  }
  if (frame->node_ids.empty()) return Error{keyframe_place(k) + ": carries no node ids"};
  return frame;
}

double Recording::duration_s() const { return static_cast<double>(ticks_.size()) * header_.simulation.tick_s(); }

std::array<std::uint64_t, kChunkTypeCount> Recording::bytes_by_type() const {
  std::array<std::uint64_t, kChunkTypeCount> bytes{};
  for (const ChunkLocation& c : scan_.chunks) {
    if (c.type < kChunkTypeCount) bytes[c.type] += c.end() - c.offset;
  }
  return bytes;
}

std::array<std::uint64_t, kChunkTypeCount> Recording::chunks_by_type() const {
  std::array<std::uint64_t, kChunkTypeCount> count{};
  for (const ChunkLocation& c : scan_.chunks) {
    if (c.type < kChunkTypeCount) ++count[c.type];
  }
  return count;
}

}  // namespace resecto::rec
