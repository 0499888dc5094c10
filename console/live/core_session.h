// CoreSession: the core on a thread of its own at its fixed rate, as in the headless real-time run,
// for a console that watches and steers it. The console only reads LiveFrames (a snapshot plus the
// core's status) from a triple buffer and sends CoreControls through an SPSC ring; pause, single and
// batch steps, slow motion and parameter changes all happen on the core's thread at a tick boundary.
// Rendering never blocks the core: neither side ever waits for the other.
#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "console/live/live_device.h"
#include "device/link/tool_input.h"
#include "rtcore/base/result.h"
#include "rtcore/concurrency/spsc_ring.h"
#include "rtcore/concurrency/triple_buffer.h"
#include "rtcore/core/fixed_step_scheduler.h"
#include "rtcore/core/simulation.h"

namespace resecto {

class LockstepDevice;
namespace rec {
class Recorder;
}

struct CoreSessionOptions {
  SimulationConfig simulation;
  LiveDeviceOptions device;
  /// The emulated board stepped with the core's ticks instead of on the link thread: the state at
  /// every tick depends only on the procedure and the commands, never on timing (tests, tutorials).
  bool lockstep = false;
  std::int64_t spin_us = kDefaultRealtimeSpinUs;
  bool realtime_priority = true;     ///< SCHED_FIFO for the core and collision threads where permitted
  std::size_t hash_capacity = 1u << 18;  ///< collision-step hashes kept for the report (an hour at 60 Hz)
  /// Stage timings the profiler's trace ring keeps (the last ones; ~6 a tick): what --trace writes.
  std::size_t trace_capacity = 1u << 16;
};

/// What the console asks the core to do, applied at the start of the core's next tick.
enum class CoreControlKind : std::uint8_t {
  kParameter,  ///< change a tissue parameter (ParameterCommand, stamped with the tick it is meant for)
  kPause,
  kResume,
  kStep,       ///< while paused: run `steps` ticks as fast as the core's spare time allows
  kSpeed,      ///< slow motion: `speed` in (0, 1] of real time
  kRecordStart,  ///< start recording to `path` (the core creates the file: one late tick at most)
  kRecordStop,   ///< finish the recording (summary and index written)
};

struct CoreControl {
  CoreControlKind kind = CoreControlKind::kPause;
  ParameterCommand parameter;
  std::uint64_t id = 0;     ///< the console's number for it, echoed back when applied
  std::uint32_t steps = 0;
  double speed = 1.0;
  std::string path;         ///< kRecordStart
};

/// Per-stage timings of the last seconds, one entry per collision step (the largest over its ticks).
inline constexpr std::size_t kStageHistoryLength = 600;  // 10 s at 60 Hz

/// The core's own state as the console shows it, published with every snapshot.
struct CoreStatus {
  std::uint64_t next_tick = 0;  ///< the tick the core runs next (== snapshot.tick when published)
  bool paused = false;
  double speed = 1.0;
  std::uint64_t pending_steps = 0;
  TissueParameters parameters;  ///< in force
  std::array<std::int64_t, kTissueParameterCount> applied_tick{};  ///< tick each last changed at, -1: never
  std::array<std::uint64_t, kTissueParameterCount> applied_id{};   ///< the CoreControl id that changed it
  /// Host receipt time of the newest device sample latched before this snapshot (steady clock, ns);
  /// 0 when the device's times are not host times (lockstep).
  std::int64_t newest_sample_host_ns = 0;
  DeviceJoints joints;          ///< as latched for the last tick
  std::uint8_t pedals = 0;
  ToolInputState input_state = ToolInputState::kNoDevice;
  std::uint64_t deadline_ticks = 0, deadline_misses = 0, resynchronizations = 0;
  double max_late_us = 0.0;
  std::array<double, kStageCount> median_us{}, p99_us{}, budget_us{};
  std::array<std::uint64_t, kStageCount> over_budget{};
  std::array<std::array<float, kStageHistoryLength>, kStageCount> history_us{};
  std::uint32_t history_count = 0;  ///< valid entries (up to kStageHistoryLength)
  std::uint32_t history_next = 0;   ///< where the next entry goes (the oldest when full)
  /// Lockstep runs: the board's counters as the core saw them.
  std::uint64_t lockstep_reports = 0, lockstep_lost = 0;
  /// Recording: whether one is running, since which tick, records lost so far, and the last
  /// finished one's figures (fixed-size text so publishing never allocates).
  bool recording = false;
  std::uint64_t recording_start_tick = 0;
  std::uint64_t recording_lost = 0;
  std::uint64_t recordings_finished = 0;
  std::uint64_t recorded_bytes = 0, recorded_ticks = 0, recorded_keyframes = 0;
  std::array<char, 512> recording_path{};
  std::array<char, 520> recording_partial_path{};  ///< where the recording grows until it is closed and renamed
  std::array<char, 512> recording_message{};  ///< the last recording error, empty when none
};

/// One published frame of the core.
struct LiveFrame {
  SimulationSnapshot snapshot;
  CoreStatus status;
};

/// The core's slowest speed (a fraction of real time); its fastest is real time.
inline constexpr double kSlowestCoreSpeed = 1.0 / 64.0;

class CoreSession {
 public:
  /// Builds the simulation and the device; starts nothing.
  static Result<std::unique_ptr<CoreSession>> create(const CoreSessionOptions& options);
  ~CoreSession();
  CoreSession(const CoreSession&) = delete;
  CoreSession& operator=(const CoreSession&) = delete;

  /// Starts the device link and the core's thread.
  void start();
  /// Stops the core's thread (at a tick boundary) and the device link.
  void stop();

  /// Console thread: queues a control; false when the ring is full (the console retries).
  bool send(const CoreControl& control) { return controls_.try_push(control); }
  /// The tick the core will run next, as last published (any thread): what "the next tick" is.
  std::uint64_t next_tick() const { return next_tick_.load(std::memory_order_acquire); }
  /// Console thread: the newest frame; update() first.
  TripleBuffer<LiveFrame>& frames() { return frames_; }

  const Simulation& simulation() const { return *sim_; }
  /// Null unless the device runs on its link thread.
  LiveDevice* live_device() { return live_.get(); }
  std::string device_description() const;
  bool realtime_priority_held() const { return priority_held_.load(std::memory_order_acquire); }

  /// After stop(): the hash at every collision step run, in order (tick, hash).
  const std::vector<std::pair<std::uint64_t, std::uint64_t>>& collision_hashes() const { return hashes_; }
  /// After stop(): how well the schedule held.
  const DeadlineReport& deadlines() const { return scheduler_.report(); }
  /// The processor the core's thread was kept on (keep_core_apart), or -1.
  int core_cpu() const { return core_cpu_.load(std::memory_order_acquire); }
  const FrameProfiler& profiler() const { return profiler_; }
  /// After stop(): the first recording that could not be started or finished whole, empty when none
  /// (the panel shows the last one; a session ends with exit 1 on this one, audit 8, G4).
  const std::string& recording_error() const { return first_recording_error_; }

 private:
  CoreSession(const CoreSessionOptions& options, std::unique_ptr<Simulation> sim);
  void run_core();
  /// The scheduler's wake hook: readies the physics helper for the coming tick if it will step.
  void prepare_for_tick();
  void take_controls();
  void step_once();
  void publish();
  void start_recording(const std::string& path);
  void finish_recording();

  CoreSessionOptions options_;
  std::unique_ptr<Simulation> sim_;
  std::unique_ptr<LiveDevice> live_;
  std::unique_ptr<LockstepDevice> lockstep_;
  std::atomic<int> core_cpu_{-1};
  FrameProfiler profiler_;
  FixedStepScheduler scheduler_;
  SpscRing<DeviceSample> samples_{4096};
  SpscRing<CoreControl> controls_{256};
  TripleBuffer<LiveFrame> frames_;
  ToolInput tool_input_;

  // Core-thread state.
  std::vector<ParameterCommand> pending_;       ///< capacity fixed at creation
  std::vector<std::uint64_t> pending_ids_;
  std::vector<ParameterCommand> due_;
  CoreStatus status_;
  std::array<float, kStageCount> since_publish_max_us_{};
  double speed_credit_ = 0.0;
  std::uint64_t publishes_ = 0;
  std::vector<std::pair<std::uint64_t, std::uint64_t>> hashes_;
  std::unique_ptr<rec::Recorder> recorder_;
  std::string first_recording_error_;
  bool have_held_sample_ = false;

  std::atomic<std::uint64_t> next_tick_{0};
  std::atomic<bool> stop_requested_{false};
  std::atomic<bool> priority_held_{false};
  std::thread thread_;
};

}  // namespace resecto
