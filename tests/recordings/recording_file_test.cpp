// The recording file: what the Recorder writes reads back bit-exactly, replays to the live hashes,
// and survives being cut at every byte and having a bit flipped in any chunk.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "recordings/recover.h"
#include "recordings/replay.h"
#include "recordings/session_header.h"
#include "tests/recordings/short_recording.h"

namespace resecto::rec {
namespace {

using testing::short_recording;

Recording open_bytes(const std::vector<std::uint8_t>& bytes) {
  Result<Recording> r = Recording::from_bytes(bytes);
  EXPECT_TRUE(r) << (r ? "" : r.error());
  return std::move(*r);
}

bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

bool is(const ChunkLocation& chunk, ChunkType type) { return chunk.type == static_cast<std::uint16_t>(type); }

TEST(RecordingFile, ReadsBackEveryInputCommandAndHashBitExactly) {
  const testing::LiveRun& live = short_recording();
  EXPECT_EQ(live.counters.ticks_lost + live.counters.steps_lost + live.counters.keyframes_lost, 0u);
  const Recording r = open_bytes(live.file);
  EXPECT_TRUE(r.index_present());
  EXPECT_TRUE(r.damaged().empty());
  EXPECT_TRUE(r.content_errors().empty());
  ASSERT_EQ(r.tick_count(), live.inputs.size());
  EXPECT_EQ(r.replayable_ticks(), live.inputs.size());
  const std::vector<TickRecord> ticks = r.all_ticks();
  ASSERT_EQ(ticks.size(), live.inputs.size());
  for (std::size_t i = 0; i < live.inputs.size(); ++i) {
    const TickInput& a = live.inputs[i];
    const TickInput& b = ticks[i].input;
    ASSERT_EQ(ticks[i].tick, i);
    EXPECT_TRUE(same_bits(a.joints.yaw_rad, b.joints.yaw_rad) && same_bits(a.joints.pitch_rad, b.joints.pitch_rad) &&
                same_bits(a.joints.roll_rad, b.joints.roll_rad) && same_bits(a.joints.insertion_m, b.joints.insertion_m) &&
                same_bits(a.joints.loop_travel_m, b.joints.loop_travel_m))
        << "tick " << i;
    EXPECT_EQ(a.cut, b.cut);
    EXPECT_EQ(a.coagulate, b.coagulate);
    EXPECT_EQ(a.tool_present, b.tool_present);
  }
  ASSERT_EQ(r.steps().size(), live.hashes.size());
  for (std::size_t i = 0; i < live.hashes.size(); ++i) EXPECT_EQ(r.steps()[i].state_hash, live.hashes[i]);
  ASSERT_EQ(r.commands().size(), live.commands.size());
  for (std::size_t i = 0; i < live.commands.size(); ++i) {
    EXPECT_EQ(r.commands()[i].apply_tick, live.commands[i].apply_tick);
    EXPECT_EQ(r.commands()[i].id, live.commands[i].id);
    EXPECT_EQ(r.commands()[i].value, live.commands[i].value);
  }
  // Keyframes every 6 collision steps: steps 0, 6, 12 of 18.
  ASSERT_EQ(r.keyframes().size(), 3u);
  EXPECT_EQ(r.keyframes()[1].tick, 6u * 16u);
  EXPECT_TRUE(r.keyframes()[0].topology_changed);
  EXPECT_TRUE(r.keyframes()[0].has_node_ids);
  EXPECT_FALSE(r.keyframes()[1].topology_changed);
  EXPECT_TRUE(r.keyframes()[1].has_node_ids);
}

TEST(RecordingFile, ReplayVerifiesEveryHashAndEndsOnTheLiveHash) {
  const testing::LiveRun& live = short_recording();
  const Recording r = open_bytes(live.file);
  auto replayer = Replayer::create(r);
  ASSERT_TRUE(replayer) << replayer.error();
  EXPECT_EQ((*replayer)->run_to(UINT64_MAX), live.inputs.size());
  EXPECT_EQ((*replayer)->verified_hashes(), live.hashes.size());
  EXPECT_EQ((*replayer)->mismatches(), 0u);
  EXPECT_EQ((*replayer)->simulation().state_hash(), live.final_hash);
}

TEST(RecordingFile, KeyframesMatchTheReplayedSurfaceWithinTheQuantisationStep) {
  const testing::LiveRun& live = short_recording();
  const Recording r = open_bytes(live.file);
  auto replayer = Replayer::create(r);
  ASSERT_TRUE(replayer);
  const double step = r.header().grid.step_m();
  for (std::size_t k = 0; k < r.keyframes().size(); ++k) {
    (*replayer)->run_to(r.keyframes()[k].tick + 1);
    const SimulationSnapshot truth = (*replayer)->simulation().make_snapshot();
    Result<SurfaceFrame> frame = r.decode_keyframe(k);
    ASSERT_TRUE(frame) << frame.error();
    ASSERT_EQ(frame->node_ids.size(), frame->positions.size());
    double worst = 0.0;
    for (std::size_t v = 0; v < frame->positions.size(); ++v) {
      ASSERT_LT(frame->node_ids[v], truth.node_count);
      const Vec3 d = frame->positions[v] - truth.node_positions[frame->node_ids[v]];
      worst = std::max({worst, std::abs(d.x), std::abs(d.y), std::abs(d.z)});
    }
    // Half a step of rounding, plus float32 storage of the dequantised value.
    EXPECT_LE(worst, 0.5 * step + 1e-6) << "keyframe " << k;
    // The triangles are the snapshot's, over node ids.
    ASSERT_EQ(frame->triangles.size(), truth.surface_triangle_count);
    std::vector<Triangle> decoded, expected(truth.surface_triangles.begin(), truth.surface_triangles.begin() + truth.surface_triangle_count);
    for (const Triangle& t : frame->triangles) decoded.push_back({frame->node_ids[t[0]], frame->node_ids[t[1]], frame->node_ids[t[2]]});
    // Draco may start each triangle at another corner; compare rotated to the smallest id first.
    for (auto* list : {&decoded, &expected}) {
      for (Triangle& t : *list) std::rotate(t.begin(), std::min_element(t.begin(), t.end()), t.end());
      std::sort(list->begin(), list->end());
    }
    EXPECT_EQ(decoded, expected) << "keyframe " << k;
  }
}

/// The chunks of `scan` as (offset, type, sequence) for comparison.
std::vector<std::tuple<std::uint64_t, std::uint16_t, std::uint32_t>> listing(const std::vector<ChunkLocation>& chunks) {
  std::vector<std::tuple<std::uint64_t, std::uint16_t, std::uint32_t>> out;
  for (const ChunkLocation& c : chunks) out.emplace_back(c.offset, c.type, c.sequence);
  return out;
}

TEST(RecordingFile, CutAtEveryByteKeepsExactlyTheWholeChunksBeforeTheCutAndRecovers) {
  const testing::LiveRun& live = short_recording();
  const ChunkScan full = scan_chunks(live.file);
  ASSERT_GT(full.chunks.size(), 20u);
  // The recovered file depends only on which whole chunks precede the cut (and, in its summary,
  // whether a cut-off tail was dropped and whether the original was closed); it is replayed once per distinct case, and every cut's
  // recovery is checked to be byte-identical to its case's.
  std::map<std::tuple<std::size_t, bool, bool>, std::vector<std::uint8_t>> recovered_by_whole_chunks;
  const std::uint64_t header_end = full.chunks.front().end();
  for (std::size_t cut = 0; cut <= live.file.size(); ++cut) {
    const std::vector<std::uint8_t> prefix(live.file.begin(), live.file.begin() + static_cast<std::ptrdiff_t>(cut));
    const ChunkScan scan = scan_chunks(prefix);
    std::vector<ChunkLocation> expected;
    for (const ChunkLocation& c : full.chunks) {
      if (c.end() <= cut) expected.push_back(c);
    }
    ASSERT_EQ(listing(scan.chunks), listing(expected)) << "cut at " << cut;
    Result<Recording> r = Recording::from_bytes(prefix);
    if (cut < header_end) {
      ASSERT_FALSE(r) << "cut at " << cut;
      // Cut inside the signature, the file is named as cut short, not as some other kind of file.
      if (cut == 0) {
        EXPECT_NE(r.error().find("the file is empty"), std::string::npos) << r.error();
      } else if (cut < 8) {
        EXPECT_NE(r.error().find("cut inside the recording's 8-byte signature"), std::string::npos) << r.error();
      }
      continue;
    }
    ASSERT_TRUE(r) << r.error();
    EXPECT_TRUE(r->content_errors().empty());
    RecoverReport report;
    const std::vector<std::uint8_t> bytes = recovered_bytes(*r, report).value();
    Result<Recording> back = Recording::from_bytes(bytes);
    ASSERT_TRUE(back);
    EXPECT_TRUE(back->index_present()) << "cut at " << cut;
    EXPECT_TRUE(back->damaged().empty()) << "cut at " << cut;
    EXPECT_EQ(back->replayable_ticks(), r->replayable_ticks());
    auto [it, first] = recovered_by_whole_chunks.try_emplace(std::tuple(expected.size(), !r->damaged().empty(), r->index_present()), bytes);
    if (!first) {
      EXPECT_EQ(it->second, bytes) << "cut at " << cut;
    }
  }
  // Each distinct recovery replays with every hash it holds verified, up to its last tick.
  for (const auto& [whole_chunks, bytes] : recovered_by_whole_chunks) {
    const Recording r = open_bytes(bytes);
    auto replayer = Replayer::create(r);
    ASSERT_TRUE(replayer);
    EXPECT_EQ((*replayer)->run_to(UINT64_MAX), r.replayable_ticks());
    EXPECT_EQ((*replayer)->mismatches(), 0u) << std::get<0>(whole_chunks) << " whole chunks";
    std::uint64_t hashes_in_range = 0;
    for (const StepEntry& s : r.steps()) hashes_in_range += s.tick < r.replayable_ticks() ? 1 : 0;
    EXPECT_EQ((*replayer)->verified_hashes(), hashes_in_range);
  }
}

TEST(RecordingFile, AFlippedBitInChunkKLosesChunkKOnly) {
  const testing::LiveRun& live = short_recording();
  const ChunkScan full = scan_chunks(live.file);
  for (std::size_t k = 0; k < full.chunks.size(); ++k) {
    const ChunkLocation& chunk = full.chunks[k];
    // One flip in the payload (or its CRC when empty), one in the frame's length field.
    for (std::uint64_t at : {chunk.payload_offset() + chunk.payload_bytes / 2, chunk.offset + 13}) {
      std::vector<std::uint8_t> bytes = live.file;
      bytes[at] ^= 0x10;
      const ChunkScan scan = scan_chunks(bytes);
      std::vector<ChunkLocation> expected = full.chunks;
      expected.erase(expected.begin() + static_cast<std::ptrdiff_t>(k));
      if (k + 1 == full.chunks.size()) {
        // The index: its loss also orphans the trailer, which the scan then reports as bytes.
        EXPECT_FALSE(scan.trailer_present);
      }
      ASSERT_EQ(listing(scan.chunks), listing(expected)) << "chunk " << k << " byte " << at;
      ASSERT_FALSE(scan.damaged.empty());
      EXPECT_EQ(scan.damaged.front().offset, chunk.offset) << "chunk " << k;
      if (chunk.type != static_cast<std::uint16_t>(ChunkType::kHeader)) {
        Result<Recording> r = Recording::from_bytes(bytes);
        ASSERT_TRUE(r) << r.error();
        EXPECT_TRUE(r->content_errors().empty());
      }
    }
  }
}

/// `bytes` with one bit flipped in the middle of `chunk`'s payload: its CRC fails and it alone is lost.
std::vector<std::uint8_t> with_payload_damaged(std::vector<std::uint8_t> bytes, const ChunkLocation& chunk) {
  bytes[chunk.payload_offset() + chunk.payload_bytes / 2] ^= 0x10;
  return bytes;
}

// A damaged keyframe leaves its number unused: the keyframes after it keep theirs (the reader
// renumbered them, so `rec export --keyframe 1` gave keyframe 2), asking for it names the damaged
// range, and the numbers hold with the index lost and after `rec recover` has dropped the chunk.
TEST(RecordingFile, KeyframesAfterADamagedOneKeepTheirNumbers) {
  const testing::LiveRun& live = short_recording();
  const Recording intact = open_bytes(live.file);
  ASSERT_EQ(intact.keyframes().size(), 3u);
  for (std::size_t k = 0; k < 3; ++k) EXPECT_EQ(intact.keyframes()[k].number, k);
  EXPECT_TRUE(intact.missing_keyframes().empty());
  const ChunkLocation middle = intact.chunks()[intact.keyframes()[1].chunk];
  const std::vector<std::uint8_t> damaged = with_payload_damaged(live.file, middle);
  ASSERT_EQ(intact.chunks().back().type, static_cast<std::uint16_t>(ChunkType::kIndex));
  const std::vector<std::uint8_t> no_index(damaged.begin(), damaged.begin() + static_cast<std::ptrdiff_t>(intact.chunks().back().offset));
  RecoverReport report;
  const std::vector<std::uint8_t> recovered = recovered_bytes(open_bytes(damaged), report).value();
  for (const auto& [bytes, name] :
       {std::pair{&damaged, "damaged.rsrec"}, std::pair{&no_index, "no_index.rsrec"}, std::pair{&recovered, "recovered.rsrec"}}) {
    Result<Recording> r = Recording::from_bytes(*bytes, name);
    ASSERT_TRUE(r) << r.error();
    ASSERT_EQ(r->keyframes().size(), 2u) << name;
    EXPECT_EQ(r->keyframes()[1].number, 2u) << name;
    EXPECT_EQ(r->keyframes()[1].tick, intact.keyframes()[2].tick) << name;
    const Result<std::size_t> two = r->find_keyframe(2);
    ASSERT_TRUE(two) << two.error();
    EXPECT_EQ(*two, 1u) << name;
    const Result<std::size_t> one = r->find_keyframe(1);
    ASSERT_FALSE(one) << name;
    EXPECT_EQ(one.error().rfind("keyframe 1 (at 0.100 s) ", 0), 0u) << one.error();
    EXPECT_EQ(r->missing_keyframes(), (std::vector<std::pair<std::uint64_t, std::uint64_t>>{{1, 1}})) << name;
    const Result<SurfaceFrame> frame = r->decode_keyframe(*two);
    ASSERT_TRUE(frame) << frame.error();
    EXPECT_EQ(frame->positions.size(), intact.keyframes()[2].vertex_count);
  }
  const std::string range = "keyframe chunk " + std::to_string(middle.sequence) + " at byte " + std::to_string(middle.offset) + " (" +
                            std::to_string(middle.end() - middle.offset) + " bytes): payload CRC mismatch";
  EXPECT_EQ(Recording::from_bytes(damaged, "damaged.rsrec")->find_keyframe(1).error(),
            "keyframe 1 (at 0.100 s) is in a damaged range of damaged.rsrec: " + range);
  EXPECT_EQ(Recording::from_bytes(no_index, "no_index.rsrec")->find_keyframe(1).error(),
            "keyframe 1 (at 0.100 s) is in a damaged range of no_index.rsrec: " + range);
  const std::string left_out = Recording::from_bytes(recovered, "recovered.rsrec")->find_keyframe(1).error();
  EXPECT_NE(left_out.find("is not in recovered.rsrec: `rec recover` made it from a damaged recording and left out its 1 damaged ranges"),
            std::string::npos)
      << left_out;
  const std::string past = intact.find_keyframe(3).error();
  EXPECT_NE(past.find("keyframe 3 does not exist (the recorder wrote 3"), std::string::npos) << past;
}

/// Replays `r` to its end; what it could not vouch for.
std::string unverified_after_replay(const Recording& r) {
  auto replayer = Replayer::create(r);
  EXPECT_TRUE(replayer);
  if (!replayer) return "no replay";
  (*replayer)->run_to((*replayer)->end_tick());
  EXPECT_EQ((*replayer)->mismatches(), 0u);
  EXPECT_GT((*replayer)->verified_hashes(), 0u);
  return unverified_hashes(r, **replayer);
}

// A recording cut short and recovered is sound (no damage left, an index, a summary), and every hash
// it holds matches; but the cut took the recorder's summary, so nothing says how many hashes the cut
// end held and the replay cannot vouch for the whole recording, nor can a second recovery's. A lost
// ticks chunk leaves the hashes after it uncompared.
TEST(RecordingFile, ARecoveredCutOrGappedRecordingDoesNotVerifyAsWhole) {
  const testing::LiveRun& live = short_recording();
  const Recording intact = open_bytes(live.file);
  EXPECT_EQ(unverified_after_replay(intact), "");

  // Cut in the summary: every tick and hash is kept, so only the unknown is left to fail it. (Where
  // a cut elsewhere falls, in ticks or steps, depends on the recorder thread's timing.)
  const auto summary =
      std::find_if(intact.chunks().begin(), intact.chunks().end(), [&](const ChunkLocation& c) { return is(c, ChunkType::kSummary); });
  ASSERT_NE(summary, intact.chunks().end());
  const std::vector<std::uint8_t> cut(live.file.begin(), live.file.begin() + static_cast<std::ptrdiff_t>(summary->offset + 30));
  RecoverReport report;
  const std::vector<std::uint8_t> recovered = recovered_bytes(open_bytes(cut), report).value();
  ASSERT_EQ(report.damaged_ranges, 1u);
  const Result<Recording> once = Recording::from_bytes(recovered, "recovered.rsrec");
  ASSERT_TRUE(once);
  EXPECT_TRUE(once->damaged().empty());
  EXPECT_EQ(once->recovered_damaged_ranges(), 1u);
  EXPECT_EQ(unverified_after_replay(*once),
            "recovered.rsrec: `resecto rec recover` made it from a damaged recording that was never closed (1 "
            "damaged ranges left out): how many hashes those held is unknown: all " +
                std::to_string(intact.steps().size()) + " collision steps' hashes in the file matched, which vouches for those alone");
  const Result<Recording> twice = Recording::from_bytes(recovered_bytes(*once, report).value(), "twice.rsrec");
  ASSERT_TRUE(twice);
  EXPECT_EQ(twice->recovered_damaged_ranges(), 1u) << "a recovery of a recovery keeps the count";
  EXPECT_NE(unverified_after_replay(*twice), "");

  // A ticks chunk from the middle of the run lost: the replay stops there.
  const auto ticks = std::find_if(intact.chunks().begin(), intact.chunks().end(), [&](const ChunkLocation& c) {
    return is(c, ChunkType::kTicks) && first_tick_of(c.type, intact.payload(c).value()) >= live.inputs.size() / 2;
  });
  ASSERT_NE(ticks, intact.chunks().end());
  const Result<Recording> gapped =
      Recording::from_bytes(recovered_bytes(open_bytes(with_payload_damaged(live.file, *ticks)), report).value(), "gapped.rsrec");
  ASSERT_TRUE(gapped);
  const std::string gap = unverified_after_replay(*gapped);
  EXPECT_NE(gap.find("recorded hashes are of collision steps at or past tick " +
                     std::to_string(first_tick_of(ticks->type, intact.payload(*ticks).value()))),
            std::string::npos)
      << gap;
}

}  // namespace
}  // namespace resecto::rec

namespace resecto::rec {
namespace {

/// A header every field of which is in range: the tests change one at a time.
SessionHeader sound_header() {
  SessionHeader header;
  header.format_version = kFormatVersion;
  header.mode = "batch";
  header.calibration = nlohmann::ordered_json::object();
  header.grid.bits = 11;
  header.grid.range = 0.1f;
  header.surface_triangles = static_cast<std::uint32_t>(header.simulation.prostate_triangles);  // the gland's, within a percent
  return header;
}

// A header whose checksums are right but whose values would make the replay build a model of
// billions of tetrahedra or buffers of billions of entries is refused by name, not attempted.
TEST(SessionHeaderJson, RefusesBoundsNoReplayCouldBuild) {
  const SessionHeader header = sound_header();
  const auto refused = [&](const char* key_path, double value) {
    nlohmann::ordered_json json = header_to_json(header);
    nlohmann::ordered_json* at = &json["simulation"];
    std::string path = key_path;
    for (std::size_t dot; (dot = path.find('.')) != std::string::npos; path = path.substr(dot + 1)) at = &(*at)[path.substr(0, dot)];
    (*at)[path] = value;
    const Result<SessionHeader> parsed = header_from_json(json.dump());
    return parsed ? std::string() : parsed.error();
  };
  EXPECT_EQ(refused("max_tet_volume_m3", 0.0), "");
  EXPECT_NE(refused("max_tet_volume_m3", 1e-30).find("tetrahedron volume bound 1e-30 m^3"), std::string::npos);
  EXPECT_NE(refused("tissue.contact_capacity.max_pair_entries", 0).find("max_pair_entries 0 is outside"), std::string::npos);
  EXPECT_NE(refused("tissue.contact_capacity.max_tissue_nodes", 1 << 30).find("max_tissue_nodes"), std::string::npos);
  // Values the command line refuses are refused here too (audit 30, F4).
  EXPECT_NE(refused("tissue.contact_margin_m", 1e6).find("contact margin 1e+09 mm is outside [0.1, 10] mm"), std::string::npos);
  nlohmann::ordered_json json = header_to_json(header);
  json["simulation"]["gimbal"]["device_to_world"] = std::vector<double>(12, 0.0);
  EXPECT_NE(header_from_json(json.dump()).error().find("device-to-world rotation is not a rotation"), std::string::npos);
  json = header_to_json(header);
  json["simulation"]["gimbal"]["pivot_m"][2] = 1e300;
  EXPECT_NE(header_from_json(json.dump()).error().find("gimbal pivot is not a finite point within 1 m"), std::string::npos);
}

// A header's counts size what the console's replay allocates: a billion nodes claimed in a file of a
// 1296-triangle gland took 23 GB and the out-of-memory killer (audit 30, F1). Now refused by name.
TEST(SessionHeaderJson, CountsPastWhatTheGlandHoldsAreRefused) {
  const SessionHeader header = sound_header();
  nlohmann::ordered_json json = header_to_json(header);
  json["nodes"] = 900000000;
  const std::string most = std::to_string(most_nodes(header.simulation));
  EXPECT_EQ(header_from_json(json.dump()).error(), "header: nodes: 900000000 is more than a gland of " + std::to_string(header.simulation.prostate_triangles) +
                                                       " triangles holds (at most " + most + ")");
  json = header_to_json(header);
  json["surface_triangles"] = 1000000000;
  EXPECT_NE(header_from_json(json.dump()).error().find("header: surface_triangles: 1000000000 is more than a gland"), std::string::npos);
  json["surface_triangles"] = header.surface_triangles;
  json["nodes"] = most_nodes(header.simulation);
  EXPECT_TRUE(header_from_json(json.dump()));
}

// A header of a 1296-triangle gland whose settings were edited to 300,000: replay built the big
// model (54 s, 2.5 GB) before refusing the counts, and `rec info` accepted it (audit 7, F3). The
// surface a recorder writes is within a percent of the triangles asked for: refused on reading.
TEST(SessionHeaderJson, ASurfaceFarSmallerThanTheSettingsGlandIsRefused) {
  nlohmann::ordered_json json = header_to_json(sound_header());
  json["surface_triangles"] = 1302;
  json["simulation"]["prostate_triangles"] = 300000;
  EXPECT_EQ(header_from_json(json.dump()).error(),
            "header: surface_triangles: 1302 is far fewer than a gland of 300000 triangles has (at least 150000): the header was edited");
  json["simulation"]["prostate_triangles"] = 1296;
  EXPECT_TRUE(header_from_json(json.dump()));
  // The recorder's own header passes for every gland it builds, the smallest included.
  for (const int triangles : {200, 1296}) {
    SimulationConfig config;
    config.prostate_triangles = triangles;
    auto sim = Simulation::create(config);
    ASSERT_TRUE(sim);
    EXPECT_GE((*sim)->prostate().surface.triangle_count(), least_surface_triangles(config)) << triangles;
  }
}

// Headers written before the contact search could keep its candidates have no contact_reuse_m: such
// a session searched at every collision step, and replays so; one set outside [0, margin) is refused.
TEST(SessionHeaderJson, ANegativeStartTickIsRefusedByName) {
  const SessionHeader header = sound_header();
  nlohmann::ordered_json json = header_to_json(header);
  json["start_tick"] = -5;
  const Result<SessionHeader> parsed = header_from_json(json.dump());
  ASSERT_FALSE(parsed);
  EXPECT_EQ(parsed.error(), "header: start_tick: must be at least 0, not -5");
  // Syntax errors carry the parser's place, without the library's exception prefix.
  const Result<SessionHeader> broken = header_from_json("{\"format_version\": ");
  ASSERT_FALSE(broken);
  EXPECT_EQ(broken.error().find("[json.exception"), std::string::npos) << broken.error();
}

// Audit 32, F1: a header whose calibration nested 50,000 levels deep (valid JSON, valid CRCs) overflowed
// the stack of every command that read it, as the document was copied; refused by where it goes deep.
TEST(SessionHeaderJson, AHeaderNestedThousandsDeepIsRefusedNotACrash) {
  nlohmann::ordered_json json = header_to_json(sound_header());
  json["calibration"] = "@";
  std::string text = json.dump();
  const std::size_t at = text.find("\"@\"");
  ASSERT_NE(at, std::string::npos);
  text.replace(at, 3, std::string(50000, '[') + std::string(50000, ']'));
  const Result<SessionHeader> parsed = header_from_json(text);
  ASSERT_FALSE(parsed);
  EXPECT_NE(parsed.error().find("header: nests arrays and objects more than 256 levels deep at line 1, column "), std::string::npos) << parsed.error();
}

TEST(SessionHeaderJson, AHeaderWithoutContactReuseReplaysSearchingEveryStep) {
  const SessionHeader header = sound_header();
  nlohmann::ordered_json json = header_to_json(header);
  EXPECT_EQ(header_from_json(json.dump())->simulation.tissue.contact_reuse_m, header.simulation.tissue.contact_reuse_m);
  json["simulation"]["tissue"].erase("contact_reuse_m");
  const Result<SessionHeader> older = header_from_json(json.dump());
  ASSERT_TRUE(older) << older.error();
  EXPECT_EQ(older->simulation.tissue.contact_reuse_m, 0.0);
  json["simulation"]["tissue"]["contact_reuse_m"] = 0.002;
  const Result<SessionHeader> refused = header_from_json(json.dump());
  ASSERT_FALSE(refused);
  EXPECT_NE(refused.error().find("contact reuse shift 2 mm"), std::string::npos) << refused.error();
}

// A hand-edited or damaged header is refused with the path of the field at fault: absent, of the
// wrong type, or out of its type's range (a negative count would otherwise wrap to four billion).
TEST(SessionHeaderJson, NamesTheFieldAtFault) {
  const SessionHeader header = sound_header();
  const nlohmann::ordered_json good = header_to_json(header);
  ASSERT_TRUE(header_from_json(good.dump()));
  const auto error_of = [](const nlohmann::ordered_json& json) {
    const Result<SessionHeader> parsed = header_from_json(json.dump());
    return parsed ? std::string("accepted") : parsed.error();
  };
  nlohmann::ordered_json json = good;
  json["simulation"]["tissue"]["max_substeps"] = "eight";
  EXPECT_EQ(error_of(json), "header: simulation.tissue.max_substeps: must be a whole number, not string");
  json = good;
  json["nodes"] = -1;
  EXPECT_EQ(error_of(json), "header: nodes: -1 is too small");
  json["nodes"] = 1.5;
  EXPECT_EQ(error_of(json), "header: nodes: must be a whole number, not 1.5");
  json["nodes"] = 4294967296.0;
  EXPECT_EQ(error_of(json), "header: nodes: 4294967296.0 is too large");
  json["nodes"] = 4096.0;  // JSON has one number type
  EXPECT_EQ(header_from_json(json.dump())->nodes, 4096u);
  json = good;
  json["simulation"]["input_filter"].erase("enabled");
  EXPECT_EQ(error_of(json), "header: simulation.input_filter.enabled: is missing");
  json = good;
  json["simulation"]["gimbal"]["pivot_m"][1] = nullptr;
  EXPECT_EQ(error_of(json), "header: simulation.gimbal.pivot_m[1]: must be a number, not null");
  json = good;
  json["simulation"]["parameters"]["stiffness"] = true;
  EXPECT_EQ(error_of(json), "header: simulation.parameters.stiffness: must be a number, not boolean");
  json = good;
  json["quantisation"] = 3;
  EXPECT_EQ(error_of(json), "header: quantisation: must be an object, not number");
  // Fields the recorder always writes, missing or out of their sense, were taken for their defaults:
  // a recording made with stiffness 100 replayed at 40 (audit 29, F7).
  json = good;
  json["simulation"]["parameters"].erase("stiffness");
  EXPECT_EQ(error_of(json), "header: simulation.parameters.stiffness: is missing");
  json = good;
  json.erase("tick_s");
  EXPECT_EQ(error_of(json), "header: tick_s: is missing");
  json = good;
  json["tick_s"] = 0.002;
  EXPECT_NE(error_of(json).find("header: tick_s: 0.002 disagrees with the rates"), std::string::npos) << error_of(json);
  json = good;
  json.erase("calibration");
  EXPECT_EQ(error_of(json), "header: calibration: is missing (the device calibration, an object)");
  json = good;
  json["mode"] = "xx";
  EXPECT_EQ(error_of(json), "header: mode: \"xx\" (batch, realtime or console)");
  json = good;
  json["simulation"]["input_filter"]["min_cutoff_hz"] = -1;
  EXPECT_EQ(error_of(json), "header: simulation.input_filter.min_cutoff_hz: must be a positive cut-off, not -1");
}

}  // namespace
}  // namespace resecto::rec

namespace resecto::rec {
namespace {

/// The file with every chunk's payload passed through `rewrite` and framed afresh (new lengths and
/// CRCs), then the trailer as it was: damage or edits that the chunk layer cannot see.
template <class Rewrite>
std::vector<std::uint8_t> with_payloads_rewritten(const std::vector<std::uint8_t>& file, Rewrite rewrite) {
  const ChunkScan scan = scan_chunks(file);
  std::vector<std::uint8_t> out(file.begin(), file.begin() + static_cast<std::ptrdiff_t>(scan.chunks.front().offset));
  for (const ChunkLocation& chunk : scan.chunks) {
    std::vector<std::uint8_t> payload(file.begin() + static_cast<std::ptrdiff_t>(chunk.payload_offset()),
                                      file.begin() + static_cast<std::ptrdiff_t>(chunk.payload_offset() + chunk.payload_bytes));
    rewrite(chunk, payload);
    append_chunk(out, static_cast<ChunkType>(chunk.type), chunk.sequence, payload);
  }
  out.insert(out.end(), file.begin() + static_cast<std::ptrdiff_t>(scan.chunks.back().end()), file.end());
  return out;
}

// A keyframe whose chunk is intact (its CRC recomputed over the damage) but whose Draco bytes do not
// decode is refused by file, keyframe and chunk, so a user can find it; the others still decode.
TEST(RecordingFile, AKeyframeThatDoesNotDecodeIsNamedByFileAndChunk) {
  const std::vector<std::uint8_t>& file = testing::short_recording().file;
  Result<Recording> intact = Recording::from_bytes(file, "session.rsrec");
  ASSERT_TRUE(intact) << intact.error();
  ASSERT_GE(intact->keyframes().size(), 3u);
  EXPECT_EQ(intact->decode_keyframe(999).error(), "session.rsrec: keyframe 999 does not exist (" + std::to_string(intact->keyframes().size()) + " recorded)");
  const std::size_t k = 1;
  const std::vector<std::uint8_t> draco = intact->keyframe_draco(k).value();
  // A keyframe's Draco bytes end its chunk's payload.
  const ChunkLocation& keyframe_chunk = intact->chunks()[intact->keyframes()[k].chunk];
  const std::size_t draco_at = keyframe_chunk.payload_offset() + keyframe_chunk.payload_bytes - draco.size();
  const std::vector<std::uint8_t> rebuilt = with_payloads_rewritten(file, [&](const ChunkLocation& chunk, std::vector<std::uint8_t>& payload) {
    if (draco_at < chunk.payload_offset() || draco_at >= chunk.payload_offset() + chunk.payload_bytes) return;
    const std::size_t from = draco_at - chunk.payload_offset();
    std::fill(payload.begin() + static_cast<std::ptrdiff_t>(from + draco.size() / 4), payload.begin() + static_cast<std::ptrdiff_t>(from + draco.size()), 0xA5);
  });
  Result<Recording> r = Recording::from_bytes(rebuilt, "session.rsrec");
  ASSERT_TRUE(r) << r.error();
  ASSERT_TRUE(r->damaged().empty());
  const ChunkLocation& chunk = r->chunks()[r->keyframes()[k].chunk];
  const Result<SurfaceFrame> frame = r->decode_keyframe(k);
  ASSERT_FALSE(frame);
  const std::string place = "session.rsrec: keyframe 1 (chunk " + std::to_string(chunk.sequence) + " at byte " + std::to_string(chunk.offset) + "): ";
  EXPECT_EQ(frame.error().substr(0, place.size()), place) << frame.error();
  EXPECT_TRUE(r->decode_keyframe(0));
  EXPECT_TRUE(r->decode_keyframe(2));
  const std::vector<std::string> problems = r->keyframe_problems();
  ASSERT_EQ(problems.size(), 1u);
  EXPECT_EQ(problems.front(), frame.error());
  EXPECT_TRUE(r->content_errors().empty()) << "a keyframe is not content the replay needs";
}

// An index whose entries do not name the chunks as they are, or chunks numbered out of order, said
// "ok ... index present" (audit 30, F4): no reader needs them, but verify vouches for the file.
TEST(RecordingFile, AnIndexOrNumberingThatDoesNotMatchTheChunksIsNamed) {
  const std::vector<std::uint8_t>& file = testing::short_recording().file;
  Result<Recording> intact = Recording::from_bytes(file, "session.rsrec");
  ASSERT_TRUE(intact) << intact.error();
  EXPECT_TRUE(intact->index_problems().empty()) << intact->index_problems().front();
  const std::vector<std::uint8_t> misindexed = with_payloads_rewritten(file, [](const ChunkLocation& chunk, std::vector<std::uint8_t>& payload) {
    if (chunk.type != static_cast<std::uint16_t>(ChunkType::kIndex)) return;
    Result<std::vector<IndexEntry>> entries = decode_index(payload);
    ASSERT_TRUE(entries) << entries.error();
    ASSERT_GT(entries->size(), 3u);
    (*entries)[2].offset += 1;
    (*entries)[3].sequence += 7;
    payload.clear();
    encode_index(*entries, payload);
  });
  Result<Recording> r = Recording::from_bytes(misindexed, "misindexed.rsrec");
  ASSERT_TRUE(r) << r.error();
  EXPECT_TRUE(r->damaged().empty());
  EXPECT_TRUE(r->content_errors().empty()) << "the chunks themselves are whole: replay and score go on";
  ASSERT_EQ(r->index_problems().size(), 2u);
  EXPECT_NE(r->index_problems()[0].find(": entry 2 (byte "), std::string::npos) << r->index_problems()[0];
  EXPECT_NE(r->index_problems()[0].find(") points where no chunk starts"), std::string::npos) << r->index_problems()[0];
  EXPECT_NE(r->index_problems()[1].find(": entry 3 (byte "), std::string::npos) << r->index_problems()[1];
  EXPECT_NE(r->index_problems()[1].find(" the file has "), std::string::npos) << r->index_problems()[1];

  // An entry that names its chunk rightly but gives it another first tick, the field a reader seeking by time uses.
  const std::vector<std::uint8_t> mistimed = with_payloads_rewritten(file, [](const ChunkLocation& chunk, std::vector<std::uint8_t>& payload) {
    if (chunk.type != static_cast<std::uint16_t>(ChunkType::kIndex)) return;
    Result<std::vector<IndexEntry>> entries = decode_index(payload);
    ASSERT_TRUE(entries) << entries.error();
    const auto ticks = std::find_if(entries->begin(), entries->end(), [](const IndexEntry& e) { return e.type == static_cast<std::uint16_t>(ChunkType::kTicks); });
    ASSERT_NE(ticks, entries->end());
    ticks->first_tick += 5;
    payload.clear();
    encode_index(*entries, payload);
  });
  Result<Recording> shifted = Recording::from_bytes(mistimed, "mistimed.rsrec");
  ASSERT_TRUE(shifted) << shifted.error();
  ASSERT_EQ(shifted->index_problems().size(), 1u);
  EXPECT_NE(shifted->index_problems()[0].find("gives the ticks chunk's first tick as 5, the chunk starts at tick 0"), std::string::npos)
      << shifted->index_problems()[0];

  // Every chunk numbered 0, framed afresh (CRCs hold); the index left out, as a killed run's file.
  const ChunkScan scan = scan_chunks(file);
  std::vector<std::uint8_t> renumbered(file.begin(), file.begin() + static_cast<std::ptrdiff_t>(scan.chunks.front().offset));
  for (const ChunkLocation& chunk : scan.chunks) {
    if (chunk.type == static_cast<std::uint16_t>(ChunkType::kIndex)) continue;
    const auto from = file.begin() + static_cast<std::ptrdiff_t>(chunk.payload_offset());
    append_chunk(renumbered, static_cast<ChunkType>(chunk.type), 0, std::span(&*from, chunk.payload_bytes));
  }
  Result<Recording> zeros = Recording::from_bytes(renumbered, "zeros.rsrec");
  ASSERT_TRUE(zeros) << zeros.error();
  ASSERT_FALSE(zeros->index_problems().empty());
  EXPECT_NE(zeros->index_problems().back().find("is numbered 0, not after the chunk before it (0): chunks reordered or renumbered"), std::string::npos)
      << zeros->index_problems().back();
  EXPECT_LE(zeros->index_problems().size(), Recording::kMostProblemsListed);
}

// A recording whose header starts past tick 0 (the console's record button, mid-session) holds no
// state to re-simulate from: replay refuses it by name and says what still works.
TEST(RecordingFile, ReplayRefusesARecordingStartedMidSessionAndSaysWhy) {
  const std::vector<std::uint8_t> rebuilt =
      with_payloads_rewritten(testing::short_recording().file, [](const ChunkLocation& chunk, std::vector<std::uint8_t>& payload) {
        if (chunk.type != static_cast<std::uint16_t>(ChunkType::kHeader)) return;
        nlohmann::ordered_json header = nlohmann::ordered_json::parse(payload.begin(), payload.end());
        header["start_tick"] = 480;
        const std::string text = header.dump();
        payload.assign(text.begin(), text.end());
      });
  Result<Recording> r = Recording::from_bytes(rebuilt, "mid.rsrec");
  ASSERT_TRUE(r) << r.error();
  ASSERT_EQ(r->header().start_tick, 480);
  const Result<std::unique_ptr<Replayer>> replayer = Replayer::create(*r);
  ASSERT_FALSE(replayer);
  EXPECT_NE(replayer.error().find("mid.rsrec starts at tick 480 (recorded from mid-session)"), std::string::npos) << replayer.error();
  EXPECT_NE(replayer.error().find("--record"), std::string::npos) << replayer.error();
}

// Two recordings joined (`cat a b > c`): the second's chunks would pass for the first's, so the file
// reads as the first recording with a content error, and recovering it keeps only the first.
TEST(RecordingFile, ASecondRecordingJoinedOnIsLeftOutAndNamed) {
  const std::vector<std::uint8_t>& file = testing::short_recording().file;
  std::vector<std::uint8_t> joined = file;
  joined.insert(joined.end(), file.begin(), file.end());
  Result<Recording> original = Recording::from_bytes(file);
  Result<Recording> r = Recording::from_bytes(joined);
  ASSERT_TRUE(original && r);
  ASSERT_EQ(r->content_errors().size(), 1u);
  EXPECT_NE(r->content_errors()[0].find("a second header"), std::string::npos) << r->content_errors()[0];
  EXPECT_EQ(r->chunks().size(), original->chunks().size());
  EXPECT_EQ(r->tick_count(), original->tick_count());
  RecoverReport report;
  Result<Recording> recovered = Recording::from_bytes(recovered_bytes(*r, report).value());
  ASSERT_TRUE(recovered);
  EXPECT_TRUE(recovered->content_errors().empty());
  EXPECT_EQ(recovered->tick_count(), original->tick_count());
}

/// Every steps chunk of `r` decoded whole, sorted by tick: what the reader kept before it read steps
/// a chunk at a time.
std::vector<StepRecord> steps_decoded_whole(const Recording& r) {
  std::vector<StepRecord> steps;
  for (const ChunkLocation& c : r.chunks()) {
    if (!is(c, ChunkType::kSteps)) continue;
    Result<std::vector<StepRecord>> block = decode_step_block(r.payload(c).value());
    EXPECT_TRUE(block) << block.error();
    if (block) steps.insert(steps.end(), block->begin(), block->end());
  }
  std::stable_sort(steps.begin(), steps.end(), [](const StepRecord& a, const StepRecord& b) { return a.tick < b.tick; });
  return steps;
}

std::vector<std::uint8_t> encoded(const StepRecord& step) {
  std::vector<std::uint8_t> bytes;
  encode_step_block(std::span(&step, 1), bytes);
  return bytes;
}

// A reader keeps a step's tick, hash and place (32 bytes), not its ~530-byte record (audit 10,
// finding 5: 38 MB of decoded steps in a 20-minute recording); the record comes from its chunk.
TEST(RecordingFile, AStepReaderReadsEveryStepsWholeRecordInAnyOrder) {
  const Recording r = open_bytes(testing::short_recording().file);
  const std::vector<StepRecord> whole = steps_decoded_whole(r);
  ASSERT_EQ(r.steps().size(), whole.size());
  ASSERT_GT(r.chunks_by_type()[static_cast<std::size_t>(ChunkType::kSteps)], 2u) << "several steps chunks to move between";
  Result<std::vector<StepRecord>> all = r.all_steps();
  ASSERT_TRUE(all) << all.error();
  ASSERT_EQ(all->size(), whole.size());
  for (std::size_t i = 0; i < whole.size(); ++i) {
    EXPECT_EQ(r.steps()[i].tick, whole[i].tick);
    EXPECT_EQ(r.steps()[i].state_hash, whole[i].state_hash);
    EXPECT_EQ(encoded((*all)[i]), encoded(whole[i])) << "step " << i;
  }
  // From both ends in turn, nearly every read in another chunk than the last: a timeline scrubbed back and forth.
  StepReader reader(r);
  for (std::size_t n = 0; n < whole.size(); ++n) {
    const std::size_t i = n % 2 == 0 ? whole.size() - 1 - n / 2 : n / 2;
    Result<StepRecord> step = reader.at(i);
    ASSERT_TRUE(step) << step.error();
    EXPECT_EQ(encoded(*step), encoded(whole[i])) << "step " << i;
  }
  const Result<StepRecord> past = reader.at(whole.size());
  ASSERT_FALSE(past);
  EXPECT_NE(past.error().find("no collision step " + std::to_string(whole.size())), std::string::npos) << past.error();
}

const ChunkLocation* first_chunk_of(const Recording& r, ChunkType type) {
  const auto c = std::find_if(r.chunks().begin(), r.chunks().end(), [&](const ChunkLocation& chunk) { return is(chunk, type); });
  return c == r.chunks().end() ? nullptr : &*c;
}

/// `original`'s chunks but its index again, then one more chunk of `type`: a copy of a chunk, as a
/// file copied together by hand could hold it.
Recording with_chunk_appended(const Recording& original, ChunkType type, std::span<const std::uint8_t> payload) {
  std::vector<std::uint8_t> bytes(std::begin(kFileSignature), std::end(kFileSignature));
  std::uint32_t sequence = 0;
  for (const ChunkLocation& c : original.chunks()) {
    if (!is(c, ChunkType::kIndex)) append_chunk(bytes, static_cast<ChunkType>(c.type), sequence++, original.payload(c).value());
  }
  append_chunk(bytes, type, sequence, payload);
  return open_bytes(bytes);
}

// The same ticks in two ticks chunks: a copy alike is harmless, but copies that differ leave a
// reader keeping either replaying inputs the run may never have had. `rec verify` said "ok" of it and
// readers kept the first silently (audit 7, F4).
TEST(RecordingFile, TicksRecordedTwiceWithDifferentInputsAreNamedWithTheirChunks) {
  const Recording original = open_bytes(testing::short_recording().file);
  const ChunkLocation* copied = first_chunk_of(original, ChunkType::kTicks);
  ASSERT_NE(copied, nullptr);
  Result<std::vector<TickRecord>> ticks = decode_tick_block(original.payload(*copied).value());
  ASSERT_TRUE(ticks && ticks->size() > 20);
  // A copy of the first ticks chunk: alike, or with ticks 5-9 moved.
  auto with_copy = [&](std::span<const TickRecord> copy) {
    std::vector<std::uint8_t> payload;
    encode_tick_block(copy, payload);
    return with_chunk_appended(original, ChunkType::kTicks, payload);
  };
  const Recording alike = with_copy(*ticks);
  EXPECT_TRUE(alike.content_errors().empty()) << alike.content_errors()[0];
  EXPECT_EQ(alike.tick_count(), original.tick_count());

  std::vector<TickRecord> moved = *ticks;
  for (std::size_t i = 5; i < 10; ++i) moved[i].input.joints.insertion_m += 0.020;
  const Recording differing = with_copy(moved);
  ASSERT_EQ(differing.content_errors().size(), 1u);
  const std::uint64_t first = (*ticks)[5].tick, last = (*ticks)[9].tick;
  const std::string expected = "ticks records of ticks " + std::to_string(first) + "-" + std::to_string(last) +
                               " are in the file twice, and differ (ticks chunks " + std::to_string(copied->sequence) + " at byte " +
                               std::to_string(copied->offset) + ", ";
  EXPECT_NE(differing.content_errors()[0].find(expected), std::string::npos) << differing.content_errors()[0];
  // The first copy in the file is the one kept, as before.
  EXPECT_EQ(differing.all_ticks()[5].input.joints.insertion_m, original.all_ticks()[5].input.joints.insertion_m);

  // Numbered where no run reaches (damage the CRCs were recomputed over): named, never counted, and
  // the tick arithmetic (duration, gaps) does not wrap.
  std::vector<TickRecord> far = *ticks;
  for (std::size_t i = 0; i < far.size(); ++i) far[i].tick = ~std::uint64_t{0} - 5 + i;
  const Recording wrapped = with_copy(far);
  ASSERT_EQ(wrapped.content_errors().size(), 1u);
  EXPECT_NE(wrapped.content_errors()[0].find("past any run"), std::string::npos) << wrapped.content_errors()[0];
  EXPECT_EQ(wrapped.tick_count(), original.tick_count());
  EXPECT_EQ(wrapped.duration_s(), original.duration_s());
  EXPECT_EQ(wrapped.missing_ticks(), 0u);
}

// The same for steps: copies that differ are named, the first in the file is the one read.
TEST(RecordingFile, StepsRecordedTwiceWithDifferentPosesAreNamedAndTheFirstIsRead) {
  const Recording original = open_bytes(testing::short_recording().file);
  const ChunkLocation* copied = first_chunk_of(original, ChunkType::kSteps);
  ASSERT_NE(copied, nullptr);
  Result<std::vector<StepRecord>> steps = decode_step_block(original.payload(*copied).value());
  ASSERT_TRUE(steps && steps->size() == 2);  // the short recording's chunks hold two steps
  auto with_copy = [&](std::span<const StepRecord> copy) {
    std::vector<std::uint8_t> payload;
    encode_step_block(copy, payload);
    return with_chunk_appended(original, ChunkType::kSteps, payload);
  };
  const Recording alike = with_copy(*steps);
  EXPECT_TRUE(alike.content_errors().empty()) << alike.content_errors()[0];
  EXPECT_EQ(alike.steps().size(), original.steps().size());

  std::vector<StepRecord> moved = *steps;
  for (StepRecord& step : moved) step.tool.sheath.translation.z += 0.020;
  const Recording differing = with_copy(moved);
  // One run, though the steps are 16 ticks apart: a copied steps chunk is one problem, not one a step.
  ASSERT_EQ(differing.content_errors().size(), 1u);
  const std::string expected = "steps records of ticks " + std::to_string((*steps)[0].tick) + "-" + std::to_string((*steps)[1].tick) +
                               " are in the file twice, and differ (steps chunks " + std::to_string(copied->sequence) + " at byte " +
                               std::to_string(copied->offset) + ", ";
  EXPECT_NE(differing.content_errors()[0].find(expected), std::string::npos) << differing.content_errors()[0];
  ASSERT_EQ(differing.steps().size(), original.steps().size());
  StepReader reader(differing);
  for (std::size_t i = 0; i < 2; ++i) EXPECT_EQ(encoded(reader.at(i).value()), encoded((*steps)[i])) << "the first copy in the file";
}

}  // namespace
}  // namespace resecto::rec
