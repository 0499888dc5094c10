// Recording size and keyframe codec speed. Reads a recording of the 8640 `demo` (RESECTO_RECORDING,
// default out/demo.rsrec, as scripts/main_job.sh writes it) and
//  - prints its bytes per minute split by content (ticks, steps, keyframes, the rest);
//  - replays it to collect real tissue surfaces (unquantised) at 20 keyframe ticks, then times Draco
//    encoding (the recorder thread's cost) and decoding (the scrubber's) over quantisation bits,
//    encoder speed and connectivity method, with the keyframe bytes as a counter and the
//    recording's bytes per minute each setting would give at 10 keyframes a second.
#include <benchmark/benchmark.h>

#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>
#include <vector>

#include "recordings/keyframe_codec.h"
#include "recordings/recording_reader.h"
#include "recordings/replay.h"

namespace resecto::rec {
namespace {

struct Surfaces {
  std::unique_ptr<Recording> recording;
  std::vector<SimulationSnapshot> frames;
  QuantisationGrid grid;
  double other_bytes_per_min = 0.0;  ///< everything but keyframes
  double minutes = 0.0;
};

const char* recording_path() {
  const char* path = std::getenv("RESECTO_RECORDING");
  return path ? path : "out/demo.rsrec";
}

Surfaces& surfaces() {
  static Surfaces s = [] {
    Surfaces out;
    Result<Recording> r = Recording::open(recording_path());
    if (!r) {
      std::fprintf(stderr, "recording_bench: %s (record one: resecto run --headless --procedure demo --record out/demo.rsrec)\n", r.error().c_str());
      std::exit(2);
    }
    out.recording = std::make_unique<Recording>(std::move(*r));
    const Recording& rec = *out.recording;
    out.grid = rec.header().grid;
    out.minutes = rec.duration_s() / 60.0;
    const auto bytes = rec.bytes_by_type();
    out.other_bytes_per_min = static_cast<double>(rec.file_bytes() - bytes[static_cast<int>(ChunkType::kKeyframe)]) / out.minutes;
    Result<std::unique_ptr<Replayer>> replayer = Replayer::create(rec);
    if (!replayer) std::exit(2);
    const std::size_t count = rec.keyframes().size();
    for (std::size_t k = 0; k < count; k += std::max<std::size_t>(1, count / 20)) {
      (*replayer)->run_to(rec.keyframes()[k].tick + 1);
      out.frames.push_back((*replayer)->simulation().make_snapshot());
    }
    return out;
  }();
  return s;
}

KeyframeCodecSettings settings_of(const benchmark::State& state) {
  KeyframeCodecSettings settings;
  settings.encode_speed = static_cast<int>(state.range(1));
  settings.decode_speed = static_cast<int>(state.range(1));
  settings.edgebreaker = state.range(2) != 0;
  return settings;
}

void BM_KeyframeEncode(benchmark::State& state) {
  Surfaces& s = surfaces();
  QuantisationGrid grid = s.grid;
  grid.bits = static_cast<int>(state.range(0));
  const KeyframeCodecSettings settings = settings_of(state);
  std::vector<std::uint8_t> out;
  std::size_t i = 0, bytes = 0, encodes = 0;
  for (auto _ : state) {
    const SimulationSnapshot& f = s.frames[i++ % s.frames.size()];
    if (!encode_keyframe(std::span(f.node_positions.data(), f.node_count), std::span(f.surface_triangles.data(), f.surface_triangle_count), grid,
                         settings, state.range(3) != 0, out)) {
      state.SkipWithError("encode failed");
      break;
    }
    bytes += out.size();
    ++encodes;
  }
  const double keyframe_bytes = static_cast<double>(bytes) / static_cast<double>(std::max<std::size_t>(1, encodes));
  state.counters["keyframe_bytes"] = keyframe_bytes;
  // Frame and keyframe header per chunk: 24 + 25 bytes.
  state.counters["MB_per_min_at_10Hz"] = ((keyframe_bytes + 49.0) * 600.0 + s.other_bytes_per_min) / 1e6;
  state.counters["step_um"] = grid.step_m() * 1e6;
}

void BM_KeyframeDecode(benchmark::State& state) {
  Surfaces& s = surfaces();
  QuantisationGrid grid = s.grid;
  grid.bits = static_cast<int>(state.range(0));
  std::vector<std::vector<std::uint8_t>> encoded(s.frames.size());
  for (std::size_t k = 0; k < s.frames.size(); ++k) {
    const SimulationSnapshot& f = s.frames[k];
    if (!encode_keyframe(std::span(f.node_positions.data(), f.node_count), std::span(f.surface_triangles.data(), f.surface_triangle_count), grid,
                         settings_of(state), state.range(3) != 0, encoded[k])) {
      state.SkipWithError("encode failed");
      return;
    }
  }
  std::size_t i = 0;
  for (auto _ : state) {
    Result<SurfaceFrame> frame = decode_keyframe(encoded[i++ % encoded.size()]);
    if (!frame) {
      state.SkipWithError("decode failed");
      break;
    }
    benchmark::DoNotOptimize(frame->positions.data());
  }
}

void codec_grid(benchmark::internal::Benchmark* b) {
  // Draco's sequential connectivity is shown once: it codes each vertex's bits nearly raw (10x larger).
  b->Args({14, 5, 0, 1});
  for (int bits : {11, 12, 14}) {
    for (int speed : {0, 1, 2, 3, 5, 7, 10}) {
      for (int ids : {0, 1}) b->Args({bits, speed, 1, ids});
    }
  }
  b->ArgNames({"bits", "speed", "edgebreaker", "ids"})->Unit(benchmark::kMillisecond)->MinTime(0.3);
}
BENCHMARK(BM_KeyframeEncode)->Apply(codec_grid);
BENCHMARK(BM_KeyframeDecode)->Apply(codec_grid);

void print_demo_size() {
  const Recording& r = *surfaces().recording;
  const auto bytes = r.bytes_by_type();
  const double minutes = r.duration_s() / 60.0;
  std::printf("\n%s: %s recording of '%s', %.2f s, %zu ticks, %zu keyframes (%.1f Hz), %d-bit grid (%.1f um)\n", recording_path(),
              r.header().mode.c_str(), r.header().procedure.c_str(), r.duration_s(), r.tick_count(), r.keyframes().size(),
              r.keyframes().size() > 1 ? static_cast<double>(r.keyframes().size() - 1) / (r.keyframes().back().time_s - r.keyframes().front().time_s) : 0.0,
              r.header().grid.bits, r.header().grid.step_m() * 1e6);
  std::printf("%-10s %12s %12s\n", "content", "bytes", "MB/min");
  for (int type = 1; type < kChunkTypeCount; ++type) {
    std::printf("%-10s %12llu %12.3f\n", std::string(chunk_type_name(static_cast<std::uint16_t>(type))).c_str(),
                static_cast<unsigned long long>(bytes[static_cast<std::size_t>(type)]), static_cast<double>(bytes[static_cast<std::size_t>(type)]) / minutes / 1e6);
  }
  std::printf("%-10s %12zu %12.3f\n", "file", r.file_bytes(), static_cast<double>(r.file_bytes()) / minutes / 1e6);
}

}  // namespace
}  // namespace resecto::rec

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  resecto::rec::surfaces();  // the replay, before any timing
  resecto::rec::print_demo_size();
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
