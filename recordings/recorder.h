// Recorder: the recording's real-time side. The core's thread hands it one record per tick and one
// per collision step through lock-free SPSC rings, and on keyframe steps copies the snapshot into a
// preallocated slot; the recorder's own thread encodes (deflate, Draco) and writes chunks, flushing
// at least every 0.75 s. The core never waits: a full ring loses the record and counts it.
#pragma once

#include <atomic>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <span>
#include <thread>
#include <vector>

#include "recordings/keyframe_codec.h"
#include "recordings/records.h"
#include "recordings/recording_writer.h"
#include "recordings/session_header.h"
#include "rtcore/concurrency/spsc_ring.h"
#include "rtcore/core/simulation.h"

namespace resecto::rec {

struct RecorderSettings {
  std::size_t tick_ring = 1u << 15;     ///< ~34 s of ticks at 960 Hz
  std::size_t step_ring = 1u << 11;     ///< ~34 s of collision steps at 60 Hz
  std::size_t command_ring = 1024;
  int keyframe_slots = 32;              ///< snapshots waiting for the encoder (a batch run outpaces it)
  int keyframe_every_steps = 6;         ///< 60 Hz collision steps / 6 = 10 Hz keyframes
  int quantisation_bits = 11;           ///< 33 um steps over the 8640 gland's 68 mm grid
  KeyframeCodecSettings codec;
  std::uint32_t ticks_per_chunk = 720;  ///< 0.75 s at 960 Hz: longer blocks deflate better
  std::uint32_t steps_per_chunk = 45;
  double flush_interval_s = 0.75;       ///< a killed process loses at most this (plus a keyframe being encoded)
};

/// What was recorded and lost; `rec info` shows the same from the summary chunk.
struct RecorderCounters {
  std::uint64_t ticks = 0, steps = 0, commands = 0, keyframes = 0;
  std::uint64_t ticks_lost = 0, steps_lost = 0, commands_lost = 0, keyframes_lost = 0;  ///< ring full
  std::uint64_t chunks = 0, bytes = 0;
  double keyframe_encode_ms_max = 0.0, keyframe_encode_ms_mean = 0.0;
  std::string write_error;  ///< the first I/O failure (recording stopped there), and where the partial file is
};

class Recorder {
 public:
  /// Creates the partial file beside `path` (RecordingWriter), writes the header (the description's
  /// simulation config is replaced by `sim`'s) and starts the recorder thread. `path` itself is
  /// replaced only by a successful finish().
  static Result<std::unique_ptr<Recorder>> start(const std::filesystem::path& path, SessionHeader description, const Simulation& sim,
                                                 const RecorderSettings& settings = {});
  ~Recorder();
  Recorder(const Recorder&) = delete;
  Recorder& operator=(const Recorder&) = delete;

  /// Core thread, before step(tick): the input and the commands the step will apply.
  void record_tick(std::uint64_t tick, const TickInput& input, std::span<const ParameterCommand> commands);
  /// Core thread, after a collision tick's step(): hash, poses, metrics, and the surface on keyframe steps.
  void record_step(const Simulation& sim);
  /// Stops the thread after it has written everything queued, then writes the summary (with
  /// `extra`, e.g. the run's final hash) and the index. Call once, from the core's thread.
  Result<RecorderCounters> finish(const nlohmann::ordered_json& extra = nullptr);
  /// Lost records so far (any thread).
  std::uint64_t lost() const;
  /// The file the chunks go to until finish() renames it over the target (any thread: set at start).
  const std::string& partial_path() const { return writer_.partial_path(); }
  /// The recorder thread, for raising its priority in real-time runs.
  std::thread::native_handle_type native_handle() { return thread_.native_handle(); }

 private:
  Recorder(const RecorderSettings& settings, const Simulation& sim);
  void run();
  bool drain();  ///< one pass over the rings; true if anything was taken
  void take_commands();  ///< from the ring into pending_commands_
  void write_ticks();
  void write_steps(std::size_t count);  ///< the first `count` pending steps, as one chunk
  void write_covered_step_blocks();     ///< whole step chunks whose ticks are all written
  void write_commands();
  void write_keyframe(int slot);
  void note_error(const Status& status);

  RecorderSettings settings_;
  RecordingWriter writer_;
  SessionHeader header_;
  int physics_per_collision_ = 16;
  SpscRing<TickRecord> ticks_;
  SpscRing<StepRecord> steps_;
  SpscRing<ParameterCommand> commands_;
  std::vector<SimulationSnapshot> keyframe_pool_;
  SpscRing<int> free_slots_;    ///< recorder -> core
  SpscRing<int> filled_slots_;  ///< core -> recorder
  // Core-side counters (written by the core thread only, read after the thread stops or relaxed).
  std::atomic<std::uint64_t> ticks_lost_{0}, steps_lost_{0}, commands_lost_{0}, keyframes_lost_{0};
  // Recorder-thread state.
  std::vector<TickRecord> pending_ticks_;
  std::vector<StepRecord> pending_steps_;
  std::vector<ParameterCommand> pending_commands_;
  std::optional<std::uint64_t> last_tick_written_;  ///< a steps chunk waits for the ticks it covers
  std::vector<std::uint8_t> payload_, draco_;
  std::vector<bool> used_nodes_;
  std::uint64_t last_topology_version_ = UINT64_MAX;
  RecorderCounters counters_;
  double encode_ms_sum_ = 0.0;
  std::atomic<bool> running_{true};
  bool finished_ = false;
  std::thread thread_;
};

}  // namespace resecto::rec
