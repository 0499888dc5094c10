// The frame-budget profiler: scoped timers around the core's stages, fixed-memory running statistics
// (median, p95, p99, max) against each stage's budget, and a ring of recent timings exported as Chrome
// trace-event JSON that Perfetto opens. It observes the step; nothing it measures feeds back into it.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

#include "rtcore/base/result.h"
#include "rtcore/base/timing_histogram.h"

namespace resecto {

/// The stages of a core tick, in execution order.
/// kTopology (resection's edit of the tissue's second copy), kRefit and kQuery run on the collision
/// thread, alongside the ticks after their own; kCollisionWait is the core's wait for them at the next
/// collision tick, and kAdopt the core's share of an edit: the edited copy taking over the front's
/// motion (Simulation).
enum class Stage : std::uint8_t { kInput, kKinematics, kCollisionWait, kAdopt, kTopology, kPhysics, kRefit, kQuery, kResponse, kPublish, kTick };
inline constexpr int kStageCount = 11;

/// Lower-case name used in reports and traces ("physics").
const char* stage_name(Stage stage);

/// Percentiles of one stage against its budget, microseconds.
struct StageStatistics {
  double median_us = 0.0;
  double p95_us = 0.0;
  double p99_us = 0.0;
  double max_us = 0.0;
  double budget_us = 0.0;
  std::uint64_t samples = 0;
  std::uint64_t over_budget = 0;
};

/// One measured stage of one tick, for the trace.
struct StageTiming {
  std::int64_t begin_ns = 0;
  std::int64_t duration_ns = 0;
  std::uint64_t tick = 0;
  Stage stage = Stage::kTick;
};

/// A span of work another thread did, for a track of its own beside the core's in the trace (the
/// console's frames): its place in time on the profiler's clock, its number, and the core's tick it
/// relates to (a frame's: the tick of the snapshot it drew).
struct TraceSpan {
  std::int64_t begin_ns = 0;
  std::int64_t duration_ns = 0;
  std::uint64_t number = 0;
  std::uint64_t tick = 0;
};

/// A track of spans: the track's name in the viewer, each span's name, and the name of its number.
struct TraceTrack {
  std::string track;
  std::string span;
  std::string number;
  std::span<const TraceSpan> spans;
};

class FrameProfiler {
 public:
  /// Budgets per stage in microseconds; the trace keeps the last `trace_capacity` stage timings
  /// (0: no trace, only the statistics).
  FrameProfiler(const std::array<double, kStageCount>& budgets_us, std::size_t trace_capacity);

  /// Monotonic clock for timings, nanoseconds (never used by the simulation itself).
  static std::int64_t now_ns();

  /// Records one stage's duration; never allocates.
  void record(Stage stage, std::uint64_t tick, std::int64_t begin_ns, std::int64_t end_ns);

  StageStatistics statistics(Stage stage) const;
  /// Sum of every recorded duration of a stage, microseconds (its mean is this over the samples).
  double total_us(Stage stage) const { return total_us_[static_cast<int>(stage)]; }
  double budget_us(Stage stage) const { return budgets_us_[static_cast<int>(stage)]; }
  /// The stage's most recent duration, microseconds (what a live plot samples).
  double last_us(Stage stage) const { return last_us_[static_cast<int>(stage)]; }
  /// Stage timings recorded so far that the trace ring no longer holds (none without a ring).
  std::uint64_t trace_dropped() const { return trace_oldest(); }
  /// How many stage timings the trace ring holds at most.
  std::uint64_t trace_capacity() const { return trace_.size(); }
  /// The least tick of the stage timings the trace ring holds (0 before any).
  std::uint64_t trace_first_tick() const;

  /// Writes the trace ring as Chrome trace-event JSON (complete "X" events, microseconds), streamed
  /// to the file in blocks: a full ring is ~470 MB of text, which a string would hold twice. `tracks`
  /// go beside the core's and the collision thread's, one thread each, on the same time axis.
  Status write_chrome_trace(const std::filesystem::path& path, std::span<const TraceTrack> tracks = {}) const;

 private:
  std::array<double, kStageCount> budgets_us_;
  std::array<double, kStageCount> total_us_{};
  std::array<TimingHistogram, kStageCount> histograms_;
  std::array<std::uint64_t, kStageCount> over_budget_{};
  std::array<double, kStageCount> last_us_{};
  /// The count of timings written before the oldest one the ring holds.
  std::uint64_t trace_oldest() const { return trace_written_ > trace_.size() ? trace_written_ - trace_.size() : 0; }

  std::vector<StageTiming> trace_;
  std::uint64_t trace_written_ = 0;
};

/// Times a scope as one stage of one tick. With RESECTO_PROFILER_DISABLED defined the macro below
/// compiles to nothing.
class ScopedStage {
 public:
  ScopedStage(FrameProfiler* profiler, Stage stage, std::uint64_t tick)
      : profiler_(profiler), stage_(stage), tick_(tick), begin_ns_(profiler ? FrameProfiler::now_ns() : 0) {}
  ~ScopedStage() {
    if (profiler_) profiler_->record(stage_, tick_, begin_ns_, FrameProfiler::now_ns());
  }
  ScopedStage(const ScopedStage&) = delete;
  ScopedStage& operator=(const ScopedStage&) = delete;

 private:
  FrameProfiler* profiler_;
  Stage stage_;
  std::uint64_t tick_;
  std::int64_t begin_ns_;
};

#ifdef RESECTO_PROFILER_DISABLED
#define RESECTO_PROFILE_STAGE(profiler, stage, tick) ((void)0)
#else
#define RESECTO_PROFILE_STAGE_CONCAT2(a, b) a##b
#define RESECTO_PROFILE_STAGE_CONCAT(a, b) RESECTO_PROFILE_STAGE_CONCAT2(a, b)
#define RESECTO_PROFILE_STAGE(profiler, stage, tick) \
  ::resecto::ScopedStage RESECTO_PROFILE_STAGE_CONCAT(resecto_stage_timer_, __LINE__)((profiler), (stage), (tick))
#endif

}  // namespace resecto
