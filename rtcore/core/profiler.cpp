// Statistics and the Chrome trace export of the frame-budget profiler.
#include "rtcore/core/profiler.h"

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cmath>
#include <cstdio>
#include <string>

#include "rtcore/base/atomic_file.h"

namespace resecto {
namespace {

/// The stages the collision thread runs get their own track in the trace.
bool runs_on_collision_thread(Stage stage) { return stage == Stage::kTopology || stage == Stage::kRefit || stage == Stage::kQuery; }

}  // namespace

const char* stage_name(Stage stage) {
  switch (stage) {
    case Stage::kInput: return "input";
    case Stage::kKinematics: return "kinematics";
    case Stage::kCollisionWait: return "collision_wait";
    case Stage::kAdopt: return "adopt";
    case Stage::kTopology: return "topology";
    case Stage::kPhysics: return "physics";
    case Stage::kRefit: return "refit";
    case Stage::kQuery: return "query";
    case Stage::kResponse: return "response";
    case Stage::kPublish: return "publish";
    case Stage::kTick: return "tick";
  }
  return "unknown";
}

FrameProfiler::FrameProfiler(const std::array<double, kStageCount>& budgets_us, std::size_t trace_capacity)
    : budgets_us_(budgets_us), trace_(trace_capacity) {}

std::int64_t FrameProfiler::now_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

void FrameProfiler::record(Stage stage, std::uint64_t tick, std::int64_t begin_ns, std::int64_t end_ns) {
  const int s = static_cast<int>(stage);
  const double us = static_cast<double>(end_ns - begin_ns) * 1e-3;
  histograms_[s].add(us);
  last_us_[s] = us;
  total_us_[s] += us;
  if (us > budgets_us_[s]) ++over_budget_[s];
  if (trace_.empty()) return;  // no trace asked for
  trace_[trace_written_ % trace_.size()] = {begin_ns, end_ns - begin_ns, tick, stage};
  ++trace_written_;
}

StageStatistics FrameProfiler::statistics(Stage stage) const {
  const int s = static_cast<int>(stage);
  const TimingHistogram& h = histograms_[s];
  return {h.quantile(0.5), h.quantile(0.95), h.quantile(0.99), h.max(), budgets_us_[s], h.count(), over_budget_[s]};
}

std::uint64_t FrameProfiler::trace_first_tick() const {
  // The least tick, not the first recorded: the collision thread's stages are recorded when its job
  // ends, after the core's stages of later ticks.
  std::uint64_t first = trace_oldest() < trace_written_ ? UINT64_MAX : 0;
  for (std::uint64_t i = trace_oldest(); i < trace_written_; ++i) first = std::min(first, trace_[i % trace_.size()].tick);
  return first;
}

Status FrameProfiler::write_chrome_trace(const std::filesystem::path& path, std::span<const TraceTrack> tracks) const {
  const std::uint64_t first = trace_oldest();
  // Time zero is the earliest event of any track.
  std::int64_t origin_ns = INT64_MAX;
  for (std::uint64_t i = first; i < trace_written_; ++i) origin_ns = std::min(origin_ns, trace_[i % trace_.size()].begin_ns);
  for (const TraceTrack& track : tracks) {
    for (const TraceSpan& span : track.spans) origin_ns = std::min(origin_ns, span.begin_ns);
  }
  if (origin_ns == INT64_MAX) origin_ns = 0;

  AtomicFile file;
  if (Status opened = file.open(path); !opened) return opened;
  std::string block;
  constexpr std::size_t kBlockBytes = 1 << 20;
  block.reserve(kBlockBytes + 256);
  const auto flush_when_full = [&]() -> Status {
    if (block.size() < kBlockBytes) return Ok{};
    Status written = file.write(block);
    block.clear();
    return written;
  };
  block += "{\"displayTimeUnit\":\"ms\",\"traceEvents\":[\n";
  block += R"({"name":"process_name","ph":"M","pid":1,"tid":1,"args":{"name":"resecto core"}},)" "\n";
  block += R"json({"name":"thread_name","ph":"M","pid":1,"tid":1,"args":{"name":"core (fixed step)"}},)json" "\n";
  block += R"json({"name":"thread_name","ph":"M","pid":1,"tid":2,"args":{"name":"collision (topology + refit + query)"}})json";
  // The other tracks' names are the program's own words, never a user's: nothing in them to escape.
  for (std::size_t k = 0; k < tracks.size(); ++k) {
    block += ",\n{\"name\":\"thread_name\",\"ph\":\"M\",\"pid\":1,\"tid\":" + std::to_string(3 + k) +
             ",\"args\":{\"name\":\"" + tracks[k].track + "\"}}";
  }
  char line[256];
  // Oldest first: the order the stages ran in.
  for (std::uint64_t i = first; i < trace_written_; ++i) {
    const StageTiming& t = trace_[i % trace_.size()];
    std::snprintf(line, sizeof line,
                  ",\n{\"name\":\"%s\",\"cat\":\"core\",\"ph\":\"X\",\"pid\":1,\"tid\":%d,\"ts\":%.3f,\"dur\":%.3f,\"args\":{\"tick\":%llu}}",
                  stage_name(t.stage), runs_on_collision_thread(t.stage) ? 2 : 1, static_cast<double>(t.begin_ns - origin_ns) * 1e-3,
                  static_cast<double>(t.duration_ns) * 1e-3, static_cast<unsigned long long>(t.tick));
    block += line;
    if (Status written = flush_when_full(); !written) return written;
  }
  for (std::size_t k = 0; k < tracks.size(); ++k) {
    const TraceTrack& track = tracks[k];
    for (const TraceSpan& span : track.spans) {
      std::snprintf(line, sizeof line, "\",\"ph\":\"X\",\"pid\":1,\"tid\":%zu,\"ts\":%.3f,\"dur\":%.3f,\"args\":{\"", 3 + k,
                    static_cast<double>(span.begin_ns - origin_ns) * 1e-3, static_cast<double>(span.duration_ns) * 1e-3);
      block += ",\n{\"name\":\"" + track.span + "\",\"cat\":\"" + track.span + line + track.number + "\":" +
               std::to_string(span.number) + ",\"tick\":" + std::to_string(span.tick) + "}}";
      if (Status written = flush_when_full(); !written) return written;
    }
  }
  block += "\n]}\n";
  if (Status written = file.write(block); !written) return written;
  return file.commit();
}

}  // namespace resecto
