// The score tracker on the core alone: the demo driven tick by tick, the tracker observing every
// collision step, checked against what the resection itself accounted and against the demo's script.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <numeric>

#include <glm/geometric.hpp>

#include "rtcore/metrics/score.h"
#include "rtcore/scenes/procedure.h"
#include "tests/support/procedure_input.h"

namespace resecto {
namespace {

struct DemoRun {
  std::unique_ptr<Simulation> sim;
  ProcedureScore score;
  std::vector<double> step_peak_force_n;  // per observation, the largest |reaction| of its ticks, measured tick by tick
  bool peak_after_last_observation = false;
};

DemoRun run_demo() {
  SimulationConfig config;
  config.prostate_triangles = 1296;
  auto sim = Simulation::create(config);
  EXPECT_TRUE(sim) << sim.error();
  Result<Procedure> demo = builtin_procedure("demo");
  EXPECT_TRUE(demo);
  Simulation& s = **sim;
  ScoreTracker tracker(s);
  const double tick_s = s.config().tick_s();
  const auto ticks = static_cast<std::uint64_t>(std::llround(demo->duration_s() / tick_s));
  DemoRun run;
  double largest = 0.0;
  for (std::uint64_t t = 0; t < ticks; ++t) {
    s.step(procedure_input(*demo, t, tick_s), {});
    const double force = glm::length(s.reaction().force_n);
    largest = std::max(largest, force);
    if (s.is_collision_tick(t)) {
      tracker.observe(s);
      run.step_peak_force_n.push_back(largest);
      largest = 0.0;
      run.peak_after_last_observation = false;
    } else if (force > 0.0 && force == s.metrics().peak_reaction_force_n) {
      run.peak_after_last_observation = true;  // until an observation covers it
    }
  }
  run.score = tracker.finish(s);
  run.sim = std::move(*sim);
  return run;
}

const DemoRun& demo_run() {
  static const DemoRun run = run_demo();
  return run;
}

TEST(Score, ReadsTheCoresTotalsAndDerivesTheRates) {
  const DemoRun& run = demo_run();
  const ProcedureMetrics& core = run.sim->metrics();
  const ScoreMetrics& m = run.score.metrics;
  EXPECT_EQ(m.resected_total_g, core.resected_total_g);
  EXPECT_EQ(m.resected_adenoma_g, core.resected_adenoma_g);
  EXPECT_EQ(m.cuts, core.cuts);
  EXPECT_EQ(m.perforations, core.perforations);
  EXPECT_GT(m.resected_adenoma_g, 0.1);
  EXPECT_NEAR(m.procedure_time_s, 10.0, 1e-6);
  EXPECT_NEAR(m.grams_per_minute, m.resected_total_g * 6.0, 1e-12);
  ASSERT_GT(m.cuts, 0u);
  EXPECT_NEAR(m.grams_per_cut, m.resected_total_g / static_cast<double>(m.cuts), 1e-12);
  // Every sample's resected mass is the core's running total: it never decreases and ends at the total.
  ASSERT_FALSE(run.score.series.empty());
  for (std::size_t i = 1; i < run.score.series.size(); ++i) EXPECT_GE(run.score.series[i].resected_g, run.score.series[i - 1].resected_g);
  EXPECT_EQ(run.score.series.back().resected_g, core.resected_total_g);
  // The pedal is down 2 s of the demo's 10 (5.0-6.3 and 7.6-8.9 with the hold to the next keyframe).
  const std::size_t cutting = static_cast<std::size_t>(std::count_if(run.score.series.begin(), run.score.series.end(),
                                                                     [](const ScoreSample& s) { return s.cutting; }));
  EXPECT_NEAR(static_cast<double>(cutting) / static_cast<double>(run.score.series.size()), m.cut_pedal_time_s / m.procedure_time_s, 0.01);
  // Lobe attribution accounts for all the adenoma.
  EXPECT_NEAR(m.lobe_adenoma_g[0] + m.lobe_adenoma_g[1] + m.lobe_adenoma_g[2], m.resected_adenoma_g, 1e-9);
}

// The force plot is sampled once per collision step, and a spike lasts a tick or two: each sample is
// the largest force of its step's ticks, so the plot's highest point is the table's peak (the turp
// debrief showed 12.3 N at the plot's top beside a 59.3 N peak).
TEST(Score, ForceSamplesHoldTheLargestForceOfTheirStep) {
  const DemoRun& run = demo_run();
  ASSERT_EQ(run.score.series.size(), run.step_peak_force_n.size());
  double highest = 0.0;
  for (std::size_t i = 0; i < run.score.series.size(); ++i) {
    EXPECT_EQ(run.score.series[i].force_n, run.step_peak_force_n[i]) << "sample " << i;
    highest = std::max(highest, run.score.series[i].force_n);
  }
  EXPECT_GT(highest, 0.0);
  if (!run.peak_after_last_observation) {
    EXPECT_EQ(highest, run.sim->metrics().peak_reaction_force_n);
  }
}

// A procedure that ends in a stroke: what the run's last collision job removes (collected at the
// end, Simulation::settle) comes after the last observation, and went to no lobe (audit 25, F2).
TEST(Score, LobesAddUpToTheAdenomaWhenTheRunEndsInAStroke) {
  Result<Procedure> demo = builtin_procedure("demo");
  ASSERT_TRUE(demo);
  int exercised = 0;
  for (const double end_s : {5.3, 5.6, 5.9, 6.2, 8.0, 8.4}) {  // the strokes cut 5.0-6.3 s and 7.6-8.9 s
    SCOPED_TRACE(end_s);
    SimulationConfig config;
    config.prostate_triangles = 1296;
    auto sim = Simulation::create(config);
    ASSERT_TRUE(sim) << sim.error();
    Simulation& s = **sim;
    ScoreTracker tracker(s);
    const double tick_s = s.config().tick_s();
    const auto ticks = static_cast<std::uint64_t>(std::llround(end_s / tick_s));
    for (std::uint64_t t = 0; t < ticks; ++t) {
      s.step(procedure_input(*demo, t, tick_s), {});
      if (s.is_collision_tick(t)) tracker.observe(s);
    }
    const double observed_g = s.metrics().resected_adenoma_g;
    s.settle();
    const ScoreMetrics m = tracker.finish(s).metrics;
    exercised += m.resected_adenoma_g > observed_g ? 1 : 0;
    EXPECT_NEAR(m.lobe_adenoma_g[0] + m.lobe_adenoma_g[1] + m.lobe_adenoma_g[2], m.resected_adenoma_g, 1e-9);
  }
  EXPECT_GT(exercised, 0) << "no run's last collision job removed anything: the case is not exercised";
}

TEST(Score, ToolPathIsAtLeastTheStraightLinesTheScriptDrawsAndSpeedIsPathOverTime) {
  const ScoreMetrics& m = demo_run().score.metrics;
  // The demo goes in 47 mm and back out: the wire travels that twice at least.
  EXPECT_GT(m.tool_path_mm, 2.0 * 47.0 * 0.95);
  EXPECT_LT(m.tool_path_mm, 2000.0);
  EXPECT_NEAR(m.tool_mean_speed_mm_s, m.tool_path_mm / m.procedure_time_s, 1e-9);
}

TEST(Score, LobeOrderFollowsTheDemo) {
  // The demo cuts the left lateral lobe (roll +90) and then the right (roll -90), never the median.
  const ScoreMetrics& m = demo_run().score.metrics;
  ASSERT_GE(m.lobe_order.size(), 2u);
  EXPECT_STREQ(kLobeNames[m.lobe_order[0]], "left_lateral");
  EXPECT_STREQ(kLobeNames[m.lobe_order[1]], "right_lateral");
  EXPECT_GT(m.lobe_adenoma_g[1], 0.0);
  EXPECT_GT(m.lobe_adenoma_g[2], 0.0);
}

TEST(Score, HeatMapAccountsForTheRemovedVolumeOnBothSides) {
  const DemoRun& run = demo_run();
  const ResectionHeatMap& map = run.score.heat_map;
  const ResectionStats& stats = run.sim->resection_stats();
  constexpr auto kAdenoma = static_cast<std::size_t>(TissueRegion::kAdenoma), kCapsule = static_cast<std::size_t>(TissueRegion::kCapsule);
  const double initial = std::accumulate(map.initial_adenoma_m3.begin(), map.initial_adenoma_m3.end(), 0.0);
  EXPECT_NEAR(initial, stats.initial_m3[kAdenoma], 1e-9 * initial);
  // Removed per cell is clamped at 0 where refinement moved a sliver across a cell boundary, so the
  // sum is at least the removed volume, and close to it.
  const double removed = std::accumulate(map.removed_adenoma_m3.begin(), map.removed_adenoma_m3.end(), 0.0);
  EXPECT_GE(removed, stats.removed_m3[kAdenoma] * (1.0 - 1e-9));
  EXPECT_LT(removed, stats.removed_m3[kAdenoma] * 1.25 + 1e-12);
  const double capsule = std::accumulate(map.removed_capsule_m3.begin(), map.removed_capsule_m3.end(), 0.0);
  EXPECT_GE(capsule, stats.removed_m3[kCapsule] * (1.0 - 1e-9));
  // Removed adenoma lies on both sides of the channel (x > 0 and x < 0).
  double left = 0.0, right = 0.0;
  for (int k = 0; k < map.nz; ++k) {
    for (int j = 0; j < map.ny; ++j) {
      for (int i = 0; i < map.nx; ++i) {
        const double x = map.origin.x + (i + 0.5) * map.cell.x;
        const double v = map.removed_adenoma_m3[static_cast<std::size_t>((k * map.ny + j) * map.nx + i)];
        (x > 0.0 ? left : right) += v;
      }
    }
  }
  EXPECT_GT(left, 0.3 * removed);
  EXPECT_GT(right, 0.3 * removed);
}

}  // namespace
}  // namespace resecto
