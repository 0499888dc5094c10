// ReplayBrowser: a recording opened in the console's replay panel. Play, pause, step and speed move a
// replay clock over the recorded time; the timeline slider scrubs it; the views then show the tissue
// of the keyframe at or before that time (decoded from its Draco bytes) with the tool at the recorded
// pose of that collision step. Verify re-simulates the whole recording through a fresh core on a
// thread of its own and compares every collision step's hash. Console thread only, except the
// verification thread, which shares nothing but its result.
#pragma once

#include <atomic>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <thread>

#include "recordings/recording_reader.h"
#include "rtcore/anatomy/prostate.h"
#include "rtcore/core/simulation.h"

namespace resecto::gui {

/// What a finished verification found.
struct ReplayVerification {
  bool done = false;
  std::string error;  ///< the replay could not run (e.g. the recording starts mid-session)
  std::uint64_t ticks = 0, verified = 0, mismatches = 0;
  std::optional<std::uint64_t> first_mismatch_tick;
  std::string unverified;  ///< recorded hashes it could not compare (rec::unverified_hashes); empty when none
};

class ReplayBrowser {
 public:
  ReplayBrowser() = default;
  ~ReplayBrowser();
  ReplayBrowser(const ReplayBrowser&) = delete;
  ReplayBrowser& operator=(const ReplayBrowser&) = delete;

  /// Opens `path`; the error names the file and what is wrong with it.
  Status open(const std::filesystem::path& path);
  bool is_open() const { return recording_ != nullptr; }
  const rec::Recording& recording() const { return *recording_; }
  const std::string& path() const { return path_; }

  void play() { playing_ = true; }
  void pause() { playing_ = false; }
  bool playing() const { return playing_; }
  /// To the next keyframe (pauses).
  void step();
  /// Playback speeds the panel's slider and the `replay speed` action take (one range for both: the
  /// action took up to 16x, the slider 4x, audit 8, G9).
  static constexpr double kMinSpeed = 0.1;
  static constexpr double kMaxSpeed = 4.0;
  void set_speed(double speed) { speed_ = speed; }
  double speed() const { return speed_; }
  /// Scrubs to `time_s` (clamped to the recording).
  void seek(double time_s);
  /// Advances the clock by `dt_s` of wall time while playing.
  void advance(double dt_s);
  double time_s() const { return time_s_; }
  double duration_s() const;

  /// The snapshot to draw for the current time: tissue of the keyframe at or before it, tool and
  /// metrics of the collision step at or before it. Decodes a keyframe only when it changes.
  const SimulationSnapshot& snapshot();
  /// The keyframe (an index into recording().keyframes(), whose `number` is the one to show) and
  /// collision step shown (after snapshot()).
  std::optional<std::size_t> keyframe_shown() const { return keyframe_shown_; }
  /// The recording's number of the keyframe shown, as `rec export --keyframe` takes it.
  std::optional<std::uint64_t> keyframe_number_shown() const {
    if (!keyframe_shown_) return std::nullopt;
    return recording_->keyframes()[*keyframe_shown_].number;
  }
  std::uint64_t step_tick_shown() const { return step_tick_shown_; }
  /// The tool as last shown by snapshot().
  const ToolPoses& shown_tool() const { return snapshot_.tool; }
  /// Whether the cutting pedal was down in the collision step shown: its pedal time grew since the
  /// step before (the steps record metrics, not pedals), so the loop glows as it did live.
  bool cutting_shown() const { return cutting_shown_; }
  /// The loop's travel out of the sheath in the step shown, metres: the loop pose's offset along the
  /// sheath's axis, as the kinematics place it.
  double loop_travel_shown_m() const;
  /// The gland the recording was made with (for the views' landmarks and colours).
  const ProstateModel& prostate() const { return prostate_; }

  /// Starts verification on a thread (once per open recording).
  void start_verification();
  bool verifying() const { return verifying_.load(std::memory_order_acquire); }
  /// Waits for a running verification (the session's end, so its report carries the result).
  void wait_for_verification() {
    if (verifier_.joinable()) verifier_.join();
  }
  /// The result once done (null before).
  const ReplayVerification* verification() const;

 private:
  void close();

  std::string path_;
  std::unique_ptr<rec::Recording> recording_;
  std::optional<rec::StepReader> steps_;  // reads recording_'s steps a chunk at a time
  ProstateModel prostate_;
  double tick_s_ = 1.0 / 960.0;
  double time_s_ = 0.0;
  double speed_ = 1.0;
  bool playing_ = false;
  SimulationSnapshot snapshot_;
  std::optional<std::size_t> keyframe_shown_;
  std::uint64_t step_tick_shown_ = 0;
  bool cutting_shown_ = false;
  std::uint64_t topology_counter_ = 0;
  std::atomic<bool> verifying_{false};
  std::atomic<bool> verified_{false};
  ReplayVerification verification_;
  std::thread verifier_;
};

}  // namespace resecto::gui
