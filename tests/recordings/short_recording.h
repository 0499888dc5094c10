// A short recording made in-process by the real Recorder from a small gland and a scripted hand,
// shared by the recording tests (cached: each test binary builds it once).
#pragma once

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "recordings/recorder.h"

namespace resecto::rec::testing {

/// A scripted hand: insert through the apex, roll, swing, cut.
inline TickInput scripted_input(std::uint64_t tick, double tick_s) {
  const double t = static_cast<double>(tick) * tick_s;
  TickInput input;
  input.tool_present = true;
  input.joints.insertion_m = 0.150 + 0.03 * std::min(t / 0.3, 1.0);
  input.joints.roll_rad = 1.2 * std::sin(3.0 * t);
  input.joints.yaw_rad = 0.02 * std::sin(5.0 * t);
  input.joints.loop_travel_m = 0.006 * (1.0 - std::cos(4.0 * t));
  input.cut = t > 0.1;
  input.coagulate = t > 0.2 && t < 0.25;
  return input;
}

/// What the live run produced, for comparison with the recording.
struct LiveRun {
  std::vector<TickInput> inputs;
  std::vector<std::uint64_t> hashes;  ///< at every collision step
  std::vector<ParameterCommand> commands;
  std::uint64_t final_hash = 0;
  std::vector<std::uint8_t> file;     ///< the recording's bytes
  RecorderCounters counters;
};

/// Records `ticks` ticks of a 1296-triangle gland with small chunks (many chunks in a small file).
inline LiveRun record_short(const std::filesystem::path& path, std::uint64_t ticks) {
  LiveRun live;
  SimulationConfig config;
  config.prostate_triangles = 1296;
  auto sim = Simulation::create(config);
  EXPECT_TRUE(sim);
  RecorderSettings settings;
  settings.ticks_per_chunk = 32;
  settings.steps_per_chunk = 2;
  SessionHeader description;
  description.procedure = "scripted";
  description.mode = "batch";
  description.calibration = nlohmann::ordered_json::object();  // the device's, informational: none drove this run
  auto recorder = Recorder::start(path, description, **sim, settings);
  EXPECT_TRUE(recorder) << (recorder ? "" : recorder.error());
  live.commands = {{40, TissueParameter::kStiffness, 45.0}, {100, TissueParameter::kSpringDamping, 2.0}};
  for (std::uint64_t tick = 0; tick < ticks; ++tick) {
    const TickInput input = scripted_input(tick, config.tick_s());
    std::vector<ParameterCommand> due;
    for (const ParameterCommand& c : live.commands) {
      if (c.apply_tick == static_cast<std::int64_t>(tick)) due.push_back(c);
    }
    (*recorder)->record_tick(tick, input, due);
    (*sim)->step(input, due);
    live.inputs.push_back(input);
    if ((*sim)->is_collision_tick(tick)) {
      (*recorder)->record_step(**sim);
      live.hashes.push_back((*sim)->state_hash());
    }
  }
  live.final_hash = (*sim)->state_hash();
  auto counters = (*recorder)->finish({{"state_hash", live.final_hash}});
  EXPECT_TRUE(counters) << (counters ? "" : counters.error());
  if (counters) live.counters = *counters;
  std::ifstream in(path, std::ios::binary);
  live.file.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  return live;
}

/// The cached short recording (0.3 s: 288 ticks, 18 collision steps, 3 keyframes).
inline const LiveRun& short_recording() {
  static const LiveRun live = [] {
    const std::filesystem::path dir = std::filesystem::temp_directory_path() / ("resecto_rec_" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir);
    LiveRun run = record_short(dir / "short.rsrec", 288);
    std::filesystem::remove_all(dir);
    return run;
  }();
  return live;
}

}  // namespace resecto::rec::testing
