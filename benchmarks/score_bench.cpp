// Scoring cost: seconds of re-simulation and scoring per recorded minute. Records the built-in `demo`
// once at a gland size (8640 triangles, the default, and 1296 for comparison) with the headless run,
// then scores that recording (console/score/rescore.h: open, replay with the tracker observing every
// collision step, verify hashes, heat map). The counter `s_per_recorded_min` is the figure a cohort's
// scoring time scales by: minutes of recordings times it, divided by the cores GNU parallel uses.
#include <benchmark/benchmark.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <string>

#include "console/headless/headless_run.h"
#include "console/score/rescore.h"

namespace resecto {
namespace {

std::string recording_for(int triangles) {
  static std::map<int, std::string> made;
  if (auto it = made.find(triangles); it != made.end()) return it->second;
  const std::filesystem::path path = std::filesystem::temp_directory_path() / ("score_bench_demo_" + std::to_string(triangles) + ".resecto");
  HeadlessOptions options;
  Result<Procedure> demo = builtin_procedure("demo");
  if (!demo) std::exit(2);
  options.procedure = *demo;
  options.simulation.prostate_triangles = triangles;
  options.record_path = path.string();
  Result<HeadlessResult> run = run_headless(options);
  if (!run) {
    std::fprintf(stderr, "score_bench: recording the demo failed: %s\n", run.error().c_str());
    std::exit(2);
  }
  return made[triangles] = path.string();
}

void BM_ScoreRecording(benchmark::State& state) {
  const std::string path = recording_for(static_cast<int>(state.range(0)));
  double recorded_s = 0.0;
  for (auto _ : state) {
    Result<RecordingScore> scored = score_recording(path);
    if (!scored) {
      state.SkipWithError(scored.error().c_str());
      return;
    }
    recorded_s = scored->score.metrics.procedure_time_s;
    benchmark::DoNotOptimize(scored->score.metrics.resected_total_g);
  }
  state.counters["recorded_s"] = recorded_s;
  // Wall seconds per iteration, per recorded minute.
  state.counters["s_per_recorded_min"] =
      benchmark::Counter(static_cast<double>(state.iterations()) * recorded_s / 60.0, benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_ScoreRecording)->Arg(1296)->Arg(8640)->Unit(benchmark::kSecond)->Iterations(2)->UseRealTime();

}  // namespace
}  // namespace resecto

BENCHMARK_MAIN();
