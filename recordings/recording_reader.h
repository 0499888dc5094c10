// Recording: a recording file opened for reading, replay and browsing (the console's replay panel
// uses this API; see recordings/README.md). Opening scans every chunk (a file with no index, cut or
// killed, reads the same way as a closed one: every whole chunk is kept, a damaged chunk is lost
// alone), parses the header, decodes the commands and checks that every other chunk decodes. The
// file's bytes stay on disk: keyframes are indexed at open and read and decoded on demand, the ticks
// (16 for each step) are kept as the file deflated them and decoded a chunk at a time by a
// TickReader, and of each collision step only its tick, hash and place are kept (a StepReader reads
// its whole record). A Recording is immutable once open.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "recordings/chunk_format.h"
#include "recordings/keyframe_codec.h"
#include "recordings/recording_bytes.h"
#include "recordings/recording_writer.h"
#include "recordings/records.h"
#include "recordings/session_header.h"
#include "rtcore/base/result.h"

namespace resecto::rec {

/// A keyframe as the index lists it.
struct KeyframeInfo {
  std::uint64_t tick = 0;        ///< the collision tick it shows (state after that tick ran)
  double time_s = 0.0;           ///< tick * tick_s: the collision step's time, as the run counts it
  std::uint64_t topology_version = 0;
  bool topology_changed = false;
  bool has_node_ids = false;     ///< always, from this recorder
  std::uint32_t vertex_count = 0;
  std::uint32_t triangle_count = 0;
  std::uint32_t draco_bytes = 0;
  std::size_t chunk = 0;         ///< into chunks()
  /// The recording's number for it (`rec export --keyframe N`): its place in the recorder's schedule,
  /// one every keyframe_every_steps collision steps from the header's start tick, so a keyframe lost
  /// to damage leaves its number unused rather than renumbering those after it. Not its index in
  /// keyframes() once one is lost.
  std::uint64_t number = 0;
};

/// A collision step as the reader keeps it: what replay verifies, and where its whole record (the
/// tool's poses and the metrics, ~530 bytes) lies for a StepReader.
struct StepEntry {
  std::uint64_t tick = 0;
  std::uint64_t state_hash = 0;
  std::size_t chunk = 0;    ///< into chunks()
  std::uint32_t slot = 0;   ///< the record's place among that chunk's
};

class TickReader;
class StepReader;

class Recording {
 public:
  /// Reads and scans `path`. An error only when there is nothing to replay from: an unreadable file
  /// or no intact header chunk; any other damage is reported by damaged(), not fatal.
  static Result<Recording> open(const std::filesystem::path& path);
  /// The same from bytes in memory (tests, fuzzing).
  static Result<Recording> from_bytes(std::vector<std::uint8_t> bytes, std::string name = "recording");

  const SessionHeader& header() const { return header_; }
  const ChunkScan& scan() const { return scan_; }
  std::span<const ChunkLocation> chunks() const { return scan_.chunks; }
  std::span<const DamagedRange> damaged() const { return scan_.damaged; }
  bool index_present() const { return scan_.trailer_present; }
  /// The intact index chunk the recorder writes when it closes the file, or null: a file without
  /// one was never closed (the run was killed), though it may replay up to where it stops.
  const ChunkLocation* index_chunk() const;
  bool closed() const { return index_present() || index_chunk() != nullptr; }
  /// What the intact chunks hold that no recorder writes: chunks whose CRCs held but whose content
  /// did not decode, a second header, the same ticks recorded twice with different content (should
  /// never happen; counted). Keyframe chunks are not among them: keyframe_problems() has those.
  std::span<const std::string> content_errors() const { return content_errors_; }
  /// What is wrong with the file's bookkeeping though every chunk is intact: index entries that do
  /// not name the chunks as they are, chunks numbered out of order. No reader needs either (replay
  /// and score go by the chunks); `rec verify` counts them as problems. At most kMostProblemsListed.
  std::span<const std::string> index_problems() const { return index_problems_; }
  static constexpr std::size_t kMostProblemsListed = 20;
  /// Why each keyframe chunk whose CRC held is unusable: its record does not decode, claims more than
  /// the gland holds, or its Draco mesh does not decode (every keyframe is decoded: this takes a while).
  /// Keyframes are pictures: the ticks, commands and hashes replay and score without them.
  std::vector<std::string> keyframe_problems() const;

  /// How many ticks are recorded (each once, whatever copies of it the file holds).
  std::uint64_t tick_count() const { return tick_count_; }
  /// The first recorded tick (0 when there is none).
  std::uint64_t first_recorded_tick() const { return tick_runs_.empty() ? 0 : tick_runs_.front().first; }
  /// Every tick recorded, sorted by tick (gaps where chunks were lost), decoded whole: 56 bytes a
  /// tick, 65 MB for 20 minutes at 960 Hz. TickReader reads them a chunk at a time.
  std::vector<TickRecord> all_ticks() const;
  /// The ticks replay can run: from the header's start tick up to the first missing one.
  std::uint64_t replayable_ticks() const { return replayable_ticks_; }
  /// The recorded collision steps, sorted by tick, each once: 32 bytes each (2.3 MB for 20 minutes
  /// at 60 Hz). A StepReader reads their whole records.
  std::span<const StepEntry> steps() const { return steps_; }
  /// Every step's whole record, in steps() order, or the error of the first chunk that no longer reads.
  Result<std::vector<StepRecord>> all_steps() const;
  std::span<const ParameterCommand> commands() const { return commands_; }
  /// The intact keyframes, by tick. Indices into this (`k` below) are not keyframe numbers once one
  /// is lost: find_keyframe() turns a number into an index.
  std::span<const KeyframeInfo> keyframes() const { return keyframes_; }
  /// The index of the keyframe numbered `number` (KeyframeInfo::number), or why the file does not
  /// hold it: in a damaged range (named), left out by `rec recover`, lost by the recorder, or past the end.
  Result<std::size_t> find_keyframe(std::uint64_t number) const;
  /// The runs of keyframe numbers (first, last) before the last intact keyframe that the file lacks.
  std::vector<std::pair<std::uint64_t, std::uint64_t>> missing_keyframes() const;
  /// The keyframe nearest before or at `time_s` (none before the first).
  std::optional<std::size_t> keyframe_at_time(double time_s) const;
  /// Decodes keyframe `k` (an index into keyframes()) to positions (with their node ids) and triangles
  /// over the positions.
  Result<SurfaceFrame> decode_keyframe(std::size_t k) const;
  /// The keyframe's Draco bytes as stored (a valid .drc file).
  Result<std::vector<std::uint8_t>> keyframe_draco(std::size_t k) const;
  /// The summary chunk's JSON (null when the run did not close the file).
  const nlohmann::ordered_json& summary() const { return summary_; }
  /// A count the recorder wrote in its summary (`ticks`, `steps`, `commands`, `keyframes`, or
  /// `lost.<kind>`): what it wrote, which the file may no longer hold. None when the file was never
  /// closed (a cut or killed run, or a recovery of one) or its summary is lost.
  std::optional<std::uint64_t> summary_count(std::string_view key) const;
  /// The signal that ended the recorded run before its procedure did ("SIGINT", from the summary),
  /// or empty: it ran to its end, or the file was never closed (nothing says).
  std::string interrupted_by() const;
  /// The damaged ranges `rec recover` left out when it made this file, over every recovery of it; 0
  /// for a file no recovery made. What they held is lost, though the file itself is sound.
  std::uint64_t recovered_damaged_ranges() const;
  /// Whether `rec recover` made this file from a damaged recording its recorder never closed: no
  /// summary says how many ticks the procedure had, so what the ranges left out held is unknown (the
  /// end of the procedure, perhaps). Replay, score and `rec verify` all say so.
  bool recovered_from_unclosed() const { return recovered_damaged_ranges() > 0 && !summary_count("ticks"); }

  /// Simulated seconds from the first recorded tick to the end of the last (a gap a recovery left
  /// counts: the procedure spans it, though its ticks are lost).
  double duration_s() const;
  /// Ticks between the first and the last recorded one that are not in the file (a gap a recovery left).
  std::uint64_t missing_ticks() const;
  /// The runs of tick numbers (first, last) the procedure had that the file lacks: from the header's
  /// start tick to the last recorded one, and past it up to the count in the recorder's summary (ticks
  /// whose chunk is damaged, was removed, or was left out by a recovery).
  std::vector<std::pair<std::uint64_t, std::uint64_t>> tick_gaps() const;
  /// tick_gaps() in words ("ticks 720-1439 and 2000 (721 ticks)"), empty when there are none.
  std::string describe_tick_gaps() const;
  /// Bytes of intact chunks (frames included) by chunk type (index = ChunkType value).
  std::array<std::uint64_t, kChunkTypeCount> bytes_by_type() const;
  std::array<std::uint64_t, kChunkTypeCount> chunks_by_type() const;
  /// A chunk's payload, read from the file; an error if the file no longer holds it as the scan found
  /// it (its CRC is checked again: the file may have been cut or overwritten since it was opened).
  Result<std::vector<std::uint8_t>> payload(const ChunkLocation& chunk) const;
  /// The file's size when it was opened.
  std::uint64_t file_bytes() const { return scan_.file_bytes; }
  /// The name errors give the recording by (its path when opened from a file).
  const std::string& name() const { return name_; }

 private:
  friend class TickReader;
  friend class StepReader;
  /// Recorded ticks [first, first + count), as one ticks chunk's payload (deflated, decoded when read)
  /// or, when the file's ticks chunks overlap (a copied chunk), all of them decoded and kept once.
  struct TickBlock {
    std::uint64_t first = 0, count = 0;
    std::vector<std::uint8_t> payload;
    std::vector<TickRecord> records;  ///< decoded already (the overlapping case), else empty
    std::size_t chunk = 0;            ///< into chunks()
  };
  /// Keeps the ticks chunks' blocks (in file order) sorted by tick; when they overlap, decodes them
  /// all and keeps each tick once (the first copy in file order), naming copies that differ among
  /// content_errors(). Then counts the ticks and their runs.
  void keep_tick_blocks(std::vector<TickBlock> in_file_order);

  static Result<Recording> from_source(RecordingBytes bytes, std::string name);
  /// Ticks from the first recorded to the last, both in.
  std::uint64_t tick_span() const;
  /// Where keyframe k's errors point: the file, the keyframe and its chunk's place in the file.
  std::string keyframe_place(std::size_t k) const;
  /// Index entries that do not match the chunks (index_problems()).
  void check_index(std::span<const IndexEntry> entries, const std::string& where);
  /// Chunks whose numbers do not rise in file order (index_problems()).
  void check_chunk_order();
  /// Sets every keyframe's number from its tick (after the keyframes are sorted).
  void number_keyframes();
  /// find_keyframe's error for a number the file lacks; `next` indexes the first keyframe numbered after it.
  std::string why_keyframe_missing(std::uint64_t number, std::size_t next) const;

  /// The payload as the scan found it, read without checking its CRC again (the scan just did).
  Result<std::vector<std::uint8_t>> read_payload(const ChunkLocation& chunk, bool check_crc) const;

  std::string name_;
  RecordingBytes bytes_{std::vector<std::uint8_t>()};
  ChunkScan scan_;
  SessionHeader header_;
  std::vector<TickBlock> tick_blocks_;
  /// The recorded ticks as runs of consecutive numbers (first, end), sorted and merged.
  std::vector<std::pair<std::uint64_t, std::uint64_t>> tick_runs_;
  std::uint64_t tick_count_ = 0;
  std::uint64_t replayable_ticks_ = 0;
  std::vector<StepEntry> steps_;
  std::vector<ParameterCommand> commands_;
  std::vector<KeyframeInfo> keyframes_;
  /// Ticks from one scheduled keyframe to the next, and the schedule's slot of keyframe 0; a period
  /// of 0 when the keyframes are off the schedule (not this recorder's) and numbered in file order.
  std::uint64_t keyframe_period_ticks_ = 0, first_keyframe_slot_ = 0;
  nlohmann::ordered_json summary_;
  std::vector<std::string> content_errors_;
  std::vector<std::string> keyframe_record_errors_;  ///< keyframe chunks whose record did not decode
  std::vector<std::string> index_problems_;
};

/// The recorded ticks in order, decoded one ticks chunk at a time: what replay and the inputs' export
/// walk through. One per thread (it holds the chunk it decoded); the Recording must outlive it.
class TickReader {
 public:
  explicit TickReader(const Recording& recording) : recording_(&recording) {}
  /// The next tick's record, or null after the last (or at a chunk that no longer decodes, which
  /// the Recording decoded once already at open: never for an unchanged build).
  const TickRecord* next();

 private:
  const Recording* recording_;
  std::size_t block_ = 0, in_block_ = 0;
  std::vector<TickRecord> decoded_;
  bool block_decoded_ = false;
};

/// Whole collision-step records by their index in Recording::steps(), read and decoded a steps chunk
/// (45 steps) at a time and the last one kept: what the console's replay panel scrubs through. One per
/// thread; the Recording must outlive it.
class StepReader {
 public:
  explicit StepReader(const Recording& recording) : recording_(&recording) {}
  /// Step i's record; an error when the file no longer holds its chunk as it was opened.
  Result<StepRecord> at(std::size_t i);

 private:
  const Recording* recording_;
  std::optional<std::size_t> chunk_;  // the chunk decoded_ holds
  std::vector<StepRecord> decoded_;
};

}  // namespace resecto::rec
