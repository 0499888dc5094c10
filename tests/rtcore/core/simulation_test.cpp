// The core as a deterministic state machine: equal inputs give equal hashes at every collision step,
// commands take effect at their tick, and the steady-state tick neither allocates nor locks.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <mutex>
#include <string>
#include <vector>

#include "rtcore/core/simulation.h"
#include "tests/support/realtime_probe.h"
#include "tests/support/small_simulation.h"

namespace resecto {
namespace {

using testing::small_config;

/// A scripted hand: insert through the apex, roll, swing into a lobe and back.
TickInput input_at(std::uint64_t tick, double tick_s) {
  const double t = static_cast<double>(tick) * tick_s;
  TickInput input;
  input.tool_present = true;
  input.joints.insertion_m = 0.130 + 0.04 * std::min(t / 1.0, 1.0);
  input.joints.roll_rad = 1.2 * std::sin(t);
  input.joints.yaw_rad = t > 1.0 ? 0.01 * std::sin(3.0 * t) : 0.0;
  input.joints.loop_travel_m = 0.006 * (1.0 - std::cos(t));
  input.cut = t > 1.5;
  return input;
}

std::vector<std::uint64_t> run_hashes(const SimulationConfig& config, std::uint64_t ticks, const std::vector<ParameterCommand>& commands = {}) {
  auto sim = Simulation::create(config);
  EXPECT_TRUE(sim) << (sim ? "" : sim.error());
  std::vector<std::uint64_t> hashes;
  for (std::uint64_t tick = 0; tick < ticks; ++tick) {
    std::vector<ParameterCommand> due;
    for (const ParameterCommand& c : commands) {
      if (c.apply_tick == static_cast<std::int64_t>(tick)) due.push_back(c);
    }
    (*sim)->step(input_at(tick, config.tick_s()), due);
    if ((*sim)->is_collision_tick(tick)) hashes.push_back((*sim)->state_hash());
  }
  return hashes;
}

TEST(Simulation, SameInputsGiveTheSameHashAtEveryCollisionStep) {
  const SimulationConfig config = small_config();
  const auto first = run_hashes(config, 2 * 960);
  const auto second = run_hashes(config, 2 * 960);
  ASSERT_EQ(first.size(), 120u);
  EXPECT_EQ(first, second);
  // The tool moved the tissue: the hashes are not all the same state.
  EXPECT_NE(first.front(), first.back());
}

TEST(Simulation, TheCollisionThreadChangesNothingButWhereTheSearchRuns) {
  // The pipeline publishes a collision step's candidates at the next collision tick whichever thread
  // searched, so the state is bit-identical with the search on the core's own thread.
  SimulationConfig threaded = small_config();
  SimulationConfig inline_search = small_config();
  inline_search.collision_thread = false;
  const auto a = run_hashes(threaded, 2 * 960);
  const auto b = run_hashes(inline_search, 2 * 960);
  ASSERT_EQ(a.size(), 120u);
  EXPECT_EQ(a, b);
}

TEST(Simulation, TheSnapshotShowsTheSurfaceTheCutsLeaveAtEveryCollisionStep) {
  // The faces a snapshot shows come listed by the collision job that edited the copy; a snapshot
  // refilled at every collision tick must hold the same faces and regions as a fresh listing of the
  // tissue the physics steps, through every cut.
  auto sim = Simulation::create(small_config());
  ASSERT_TRUE(sim) << sim.error();
  SimulationSnapshot snapshot = (*sim)->make_snapshot();
  const std::uint64_t version_before = (*sim)->tissue().topology_version();
  std::vector<Triangle> fresh((*sim)->tissue().surface_face_capacity());
  std::vector<TissueRegion> fresh_regions(fresh.size());
  int compared = 0;
  for (std::uint64_t tick = 0; tick < 3 * 960; ++tick) {
    (*sim)->step(input_at(tick, (*sim)->config().tick_s()), {});
    if (!(*sim)->is_collision_tick(tick)) continue;
    (*sim)->fill_snapshot(snapshot);
    const std::size_t count = (*sim)->tissue().list_mesh_surface(fresh, fresh_regions);
    ASSERT_EQ(snapshot.surface_triangle_count, count) << "tick " << tick;
    for (std::size_t f = 0; f < count; ++f) {
      ASSERT_EQ(snapshot.surface_triangles[f], fresh[f]) << "tick " << tick << " face " << f;
      ASSERT_EQ(snapshot.surface_regions[f], fresh_regions[f]) << "tick " << tick << " face " << f;
    }
    ++compared;
  }
  EXPECT_EQ(compared, 180);
  EXPECT_GT((*sim)->tissue().topology_version(), version_before) << "the script must cut for this to test anything";
  EXPECT_GT((*sim)->metrics().cuts, 0u);
}

TEST(Simulation, ThePhysicsHelperChangesNoBit) {
  // The physics step's loops shared with a helper thread give the lone thread's state at every
  // collision step, through contact and cuts (input_at presses the pedal from 1.5 s), with the search
  // inline (the helper shares every tick) and on the collision thread (only ticks without its job).
  for (const bool collision_thread : {false, true}) {
    SimulationConfig alone = small_config(), shared = small_config();
    alone.collision_thread = shared.collision_thread = collision_thread;
    shared.physics_threads = 2;
    const auto a = run_hashes(alone, 2 * 960);
    const auto b = run_hashes(shared, 2 * 960);
    ASSERT_EQ(a.size(), 120u);
    EXPECT_EQ(a, b) << (collision_thread ? "collision thread" : "inline search");
  }
  SimulationConfig shared = small_config();
  shared.collision_thread = false;
  shared.physics_threads = 2;
  auto sim = Simulation::create(shared);
  ASSERT_TRUE(sim) << sim.error();
  for (std::uint64_t tick = 0; tick < 960; ++tick) (*sim)->step(input_at(tick, shared.tick_s()), {});
  ASSERT_NE((*sim)->physics_helper(), nullptr);
  EXPECT_GT((*sim)->physics_helper()->chunks_helped(), 0u) << "the helper never ran a chunk: the comparison above proved nothing";
}

TEST(Simulation, ABatchRunLeavesTheCollisionJobItsProcessor) {
  // Batch ticks come back to back: a tick stepped while the collision job runs does not call the
  // helper in (the job keeps the second processor), and the others share their loops. A plain tick
  // launches no job, so one running both before and after the step ran throughout it: the helper,
  // called in only by the job's end, ran none of that step's chunks.
  SimulationConfig config = small_config();
  config.collision_thread = true;
  config.physics_threads = 2;
  auto sim = Simulation::create(config);
  ASSERT_TRUE(sim) << sim.error();
  const LoopHelper& helper = *(*sim)->physics_helper();
  JobThread& job = *(*sim)->collision_thread();
  int beside_job = 0;
  for (std::uint64_t tick = 0; tick < 2 * 960; ++tick) {
    const bool plain = !(*sim)->is_collision_tick(tick);
    const bool running_before = !job.idle();
    const std::uint64_t helped = helper.chunks_helped();
    (*sim)->step(input_at(tick, config.tick_s()), {});
    if (plain && running_before && !job.idle()) {
      ++beside_job;
      EXPECT_EQ(helper.chunks_helped(), helped) << "the helper ran chunks of tick " << tick << " beside the running job";
    }
  }
  EXPECT_GT(beside_job, 0) << "no tick ran beside the job: nothing was tested";
  EXPECT_GT(helper.chunks_offered(), 0u) << "ticks without the job share their loops";
}

TEST(Simulation, APacedCoreThatStopsWaitingGivesUpTheHelper) {
  // Batch ticks (never paced) always share; once paced, a core that waited before fewer than half of
  // its last 32 ticks runs alone, until it keeps time again.
  SimulationConfig config = small_config();
  config.collision_thread = false;
  config.physics_threads = 2;
  auto sim = Simulation::create(config);
  ASSERT_TRUE(sim) << sim.error();
  LoopHelper& helper = *(*sim)->physics_helper();
  std::uint64_t tick = 0;
  auto run = [&](int ticks, bool waiting) {
    for (int k = 0; k < ticks; ++k, ++tick) {
      if (waiting) (*sim)->prepare_for_tick();
      (*sim)->step(input_at(tick, config.tick_s()), {});
    }
  };
  run(40, false);
  EXPECT_GT(helper.chunks_offered(), 0u) << "batch ticks share their loops";
  (*sim)->set_paced();
  run(20, true);
  const std::uint64_t on_time = helper.chunks_offered();
  run(1, false);
  EXPECT_GT(helper.chunks_offered(), on_time) << "one tick behind is a catch-up, not an overload";
  run(20, false);  // now behind for 21 of the last 32
  const std::uint64_t overloaded = helper.chunks_offered(), helped = helper.chunks_helped();
  run(20, false);
  EXPECT_EQ(helper.chunks_offered(), overloaded) << "overloaded: no loop is offered to the helper";
  EXPECT_EQ(helper.chunks_helped(), helped);
  run(32, true);
  const std::uint64_t recovered = helper.chunks_offered();
  run(1, true);
  EXPECT_GT(helper.chunks_offered(), recovered) << "keeping time again, the core shares again";
}

TEST(Simulation, ClearanceCertificatesGiveTheBruteForceState) {
  // Both tool parts, rolling, inserting and swinging into a lobe: skipping the points proven clear
  // of the tool changes no bit of the state.
  SimulationConfig brute_force = small_config();
  brute_force.tissue.clearance_certificates = false;
  const auto a = run_hashes(small_config(), 3 * 960);
  const auto b = run_hashes(brute_force, 3 * 960);
  ASSERT_EQ(a.size(), 180u);
  EXPECT_EQ(a, b);
  auto sim = Simulation::create(small_config());
  ASSERT_TRUE(sim) << sim.error();
  for (std::uint64_t tick = 0; tick < 3 * 960; ++tick) (*sim)->step(input_at(tick, (*sim)->config().tick_s()), {});
  EXPECT_GT((*sim)->metrics().contact_time_s, 0.5) << "the hand pressed the tissue for a while";
}

TEST(Simulation, ContactWaitsForTheCandidatesOfThePreviousCollisionStep) {
  // The one-step pipeline: a tool pressed in at tick 0 finds nothing before the second collision
  // tick publishes what the first one searched.
  auto sim = Simulation::create(small_config());
  ASSERT_TRUE(sim) << sim.error();
  const double h = (*sim)->config().tick_s();
  TickInput pressed = input_at(static_cast<std::uint64_t>(1.2 / h), h);  // in a lobe
  pressed.joints.yaw_rad = 0.05;
  int first_contact_tick = -1;
  for (int tick = 0; tick < 64 && first_contact_tick < 0; ++tick) {
    (*sim)->step(pressed, {});
    if ((*sim)->tissue().tool().stats().penetrating > 0) first_contact_tick = tick;
  }
  EXPECT_EQ(first_contact_tick, 16);
}

TEST(Simulation, CountsToolMotionFasterThanTheContactMarginCovers) {
  // A hand at 30 mm/s stays within the 1.5 mm margin over two collision periods (45 mm/s; the input
  // smoothing's catch-up after the start briefly runs the tool a little faster than the hand). A
  // hand that plunges at 200 mm/s outruns it, and the metrics say so.
  auto run = [](double insertion_speed_m_s) {
    auto sim = Simulation::create(small_config());
    EXPECT_TRUE(sim) << (sim ? "" : sim.error());
    const double h = (*sim)->config().tick_s();
    for (std::uint64_t tick = 0; tick < 960; ++tick) {
      TickInput input = input_at(tick, h);
      input.joints.insertion_m = 0.130 + std::min(insertion_speed_m_s * static_cast<double>(tick) * h, 0.04);
      (*sim)->step(input, {});
    }
    return (*sim)->metrics();
  };
  const ProcedureMetrics calm = run(0.03), hasty = run(0.2);

  EXPECT_GT(calm.max_tool_travel_since_search_mm, 0.0);
  EXPECT_LT(calm.max_tool_travel_since_search_mm, 1.5);
  EXPECT_EQ(calm.contact_margin_exceeded_ticks, 0u);
  EXPECT_GT(hasty.max_tool_travel_since_search_mm, 1.5);
  EXPECT_GT(hasty.contact_margin_exceeded_ticks, 0u);
}

TEST(Simulation, SearchingWhereTheToolWillBeCoversTwiceTheSpeed) {
  // Strokes in and out of 10 mm amplitude peaking at 80 mm/s: beyond the 45 mm/s that the margin
  // covers when the search looks where the tool is now, within what it covers when the search looks
  // where the tool will be while its candidates are in use.
  auto run = [](bool predict) {
    SimulationConfig config = small_config();
    config.predict_search_pose = predict;
    auto sim = Simulation::create(config);
    EXPECT_TRUE(sim) << (sim ? "" : sim.error());
    const double h = (*sim)->config().tick_s();
    for (std::uint64_t tick = 0; tick < 2 * 960; ++tick) {
      TickInput input;
      input.tool_present = true;
      input.joints.insertion_m = 0.150 - 0.010 * std::cos(8.0 * static_cast<double>(tick) * h);  // from rest
      (*sim)->step(input, {});
    }
    return (*sim)->metrics();
  };
  const ProcedureMetrics here = run(false), ahead = run(true);
  EXPECT_GT(here.contact_margin_exceeded_ticks, 100u);
  EXPECT_GT(here.max_tool_travel_since_search_mm, 2.0);
  EXPECT_EQ(ahead.contact_margin_exceeded_ticks, 0u);
  EXPECT_LT(ahead.max_tool_travel_since_search_mm, 1.3);
  std::printf("travel since search: %.2f mm (%llu ticks over the margin) here, %.2f mm (%llu) ahead\n", here.max_tool_travel_since_search_mm,
              static_cast<unsigned long long>(here.contact_margin_exceeded_ticks), ahead.max_tool_travel_since_search_mm,
              static_cast<unsigned long long>(ahead.contact_margin_exceeded_ticks));
}

TEST(Simulation, SmoothsTheDevicesNoiseBeforeItPlacesTheTool) {
  // A still hand on a device whose sheath reading has the emulated potentiometer's 0.18 mm RMS noise:
  // raw, the sheath's tip jumps by tenths of a millimetre a tick; smoothed, by hundredths.
  auto jitter = [](bool smoothed) {
    SimulationConfig config = small_config();
    config.input_filter.enabled = smoothed;
    config.collision_thread = false;
    auto sim = Simulation::create(config);
    EXPECT_TRUE(sim) << (sim ? "" : sim.error());
    std::uint64_t state = 12345;
    double largest_step_m = 0.0;
    Vec3 previous(0.0);
    for (std::uint64_t tick = 0; tick < 960; ++tick) {
      TickInput input;
      input.tool_present = true;
      // Deterministic noise: the sum of four uniform draws, scaled to 0.18 mm RMS.
      double sum = 0.0;
      for (int k = 0; k < 4; ++k) {
        state = state * 6364136223846793005ull + 1442695040888963407ull;
        sum += static_cast<double>(state >> 11) / 9007199254740992.0 - 0.5;
      }
      input.joints.insertion_m = 0.140 + 0.00018 * sum / std::sqrt(4.0 / 12.0);
      (*sim)->step(input, {});
      const Vec3 tip = (*sim)->tool_poses().sheath.translation;
      if (tick > 480) largest_step_m = std::max(largest_step_m, length(tip - previous));
      previous = tip;
    }
    return largest_step_m;
  };
  const double raw_m = jitter(false), smoothed_m = jitter(true);
  EXPECT_GT(raw_m, 0.0003);
  EXPECT_LT(smoothed_m, 0.00005) << "largest tick-to-tick step of the tip " << smoothed_m * 1e3 << " mm (raw " << raw_m * 1e3 << " mm)";
}

TEST(Simulation, ACommandChangesTheStateFromItsTickOn) {
  const SimulationConfig config = small_config();
  ParameterCommand stiffer;
  stiffer.apply_tick = 960;  // the 60th collision step
  stiffer.id = TissueParameter::kStiffness;
  stiffer.value = 2.0 * TissueParameters().get(TissueParameter::kStiffness);
  const auto plain = run_hashes(config, 1200);
  const auto changed = run_hashes(config, 1200, {stiffer});
  ASSERT_EQ(plain.size(), changed.size());
  // Collision step 60 is tick 960 itself, hashed after the command applied: the first to differ.
  for (std::size_t i = 0; i < 60; ++i) EXPECT_EQ(plain[i], changed[i]) << "collision step " << i;
  EXPECT_NE(plain.back(), changed.back());
}

class SteadyState : public ::testing::TestWithParam<int> {};

TEST_P(SteadyState, TickAllocatesNothingAndTakesNoLock) {
  SimulationConfig config = small_config();
  config.physics_threads = GetParam();
  auto sim = Simulation::create(config);
  ASSERT_TRUE(sim) << sim.error();
  const double h = (*sim)->config().tick_s();
  FrameProfiler profiler(default_stage_budgets_us((*sim)->config()), 1 << 14);
  // The pedal stays up: ticks that cut are resection_test's (their physics ticks allocate nothing;
  // a decayed sphere tree's rebuild at a collision tick does).
  auto pressing = [h](std::uint64_t tick) {
    TickInput input = input_at(tick, h);
    input.cut = false;
    return input;
  };
  // Warm up: the first contacts size the buffers that later ticks reuse.
  std::uint64_t tick = 0;
  for (; tick < 960; ++tick) (*sim)->step(pressing(tick), {}, &profiler);
  long allocations = 0, locks = 0;
  {
    testing::RealtimeProbe probe;
    for (; tick < 1920; ++tick) (*sim)->step(pressing(tick), {}, &profiler);
    allocations = probe.allocations();
    locks = probe.locks();
  }
  EXPECT_EQ(allocations, 0);
  EXPECT_EQ(locks, 0);
  EXPECT_GT((*sim)->metrics().contact_time_s, 0.0);  // the ticks counted did real contact work
}

INSTANTIATE_TEST_SUITE_P(PhysicsThreads, SteadyState, ::testing::Values(1, 2), [](const ::testing::TestParamInfo<int>& info) {
  return info.param == 1 ? std::string("Alone") : std::string("WithTheHelper");
});

TEST(RealtimeProbe, SeesAnAllocationAndALock) {
  // The probe itself must be able to fail: a heap allocation and a mutex are counted.
  std::mutex mutex;
  testing::RealtimeProbe probe;
  auto* value = new int(7);
  { std::lock_guard<std::mutex> lock(mutex); }
  delete value;
  EXPECT_GE(probe.allocations(), 1);
  EXPECT_GE(probe.locks(), 1);
}

TEST(Simulation, ContactRoomGrowsWithTheGland) {
  // The 138,240-triangle demo overflowed the default room for candidate nodes at 339 collision steps,
  // dropping contacts (a peak force of 69 N instead of 5): the room follows the surface's size.
  SimulationConfig config = small_config();
  const ToolContactCapacity defaults = config.tissue.contact_capacity;
  const ToolContactCapacity small = tissue_config_for(config).contact_capacity;
  EXPECT_EQ(small.max_tissue_nodes, defaults.max_tissue_nodes);
  EXPECT_EQ(small.max_pair_entries, defaults.max_pair_entries);
  config.prostate_triangles = 138240;
  const ToolContactCapacity fine = tissue_config_for(config).contact_capacity;
  EXPECT_EQ(fine.max_tissue_nodes, 69120);  // about every surface node
  EXPECT_EQ(fine.max_pair_entries, 552960);
  EXPECT_EQ(fine.max_tool_vertices, defaults.max_tool_vertices);  // the tool does not grow
  // A room set larger is kept; the largest gland stays within what validate() allows.
  config.tissue.contact_capacity.max_tissue_nodes = 100000;
  EXPECT_EQ(tissue_config_for(config).contact_capacity.max_tissue_nodes, 100000);
  config.prostate_triangles = 1000000;
  config.tissue.contact_capacity = tissue_config_for(config).contact_capacity;
  EXPECT_EQ(config.tissue.contact_capacity.max_pair_entries, 4000000);
  EXPECT_TRUE(config.validate());
}

// The registration's reach is the calibration file's, axis by axis: a translation of (900, 900, 0) mm,
// which a calibration file may hold, was refused as 1.27 m away by a length check.
TEST(SimulationConfig, RegistrationReachIsTheCalibrationFilesOnEachAxis) {
  SimulationConfig config;
  config.gimbal.device_to_world.translation = Vec3(0.9, 0.9, 0.0);
  config.gimbal.pivot_m = Vec3(-0.9, 0.9, 0.9);
  EXPECT_TRUE(config.validate()) << config.validate().error();
  config.gimbal.device_to_world.translation = Vec3(0.0, 1.2, 0.0);
  EXPECT_NE(config.validate().error().find("device-to-world translation is not a finite offset within 1 m"), std::string::npos);
  config.gimbal.device_to_world.translation = Vec3(0.0);
  config.gimbal.pivot_m = Vec3(0.0, 0.0, std::nan(""));
  EXPECT_NE(config.validate().error().find("gimbal pivot is not a finite point within 1 m"), std::string::npos);
}

TEST(Simulation, RejectsImpossibleRates) {
  SimulationConfig config = small_config();
  config.physics_per_collision = 0;
  auto sim = Simulation::create(config);
  ASSERT_FALSE(sim);
  EXPECT_NE(sim.error().find("physics substeps 0"), std::string::npos);
  config = small_config();
  config.physics_threads = 3;
  auto three = Simulation::create(config);
  ASSERT_FALSE(three);
  EXPECT_NE(three.error().find("physics threads 3"), std::string::npos);
}

}  // namespace
}  // namespace resecto
