// Resection's costs through the core: the topology update of one collision step while the loop cuts
// a lateral lobe (median and p99 of the profiler's `topology` stage, and per removed tetrahedron) at
// 8640 and 34560 triangles, and the physics step's median on the gland after the full `turp` against
// the uncut gland, the tool withdrawn in both.
#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdio>
#include <memory>

#include "rtcore/core/simulation.h"
#include "rtcore/scenes/procedure.h"
#include "tests/support/procedure_input.h"

namespace resecto {
namespace {

// Into the left lateral lobe, the loop drawn back twice (as the tests' stroke, twice as long).
constexpr const char* kStrokes = R"(
0.0   0.0  0.0   0.0  125.0  0.0  0 0
1.0   0.0  0.0   0.0  165.0  0.0  0 0
1.4   0.0  0.0  90.0  165.0  0.0  0 0
1.8   1.0  0.0  90.0  165.0 14.0  0 0
1.9   1.0  0.0  90.0  165.0 14.0  1 0
3.0   1.0  0.0  90.0  165.0  1.0  1 0
3.2   1.5  0.0  70.0  165.0 14.0  0 0
3.3   1.5  0.0  70.0  165.0 14.0  1 0
4.4   1.5  0.0  70.0  165.0  1.0  1 0
4.6   1.5  0.0  70.0  165.0  0.0  0 0
)";

std::unique_ptr<Simulation> simulation(int triangles) {
  SimulationConfig config;
  config.prostate_triangles = triangles;
  auto sim = Simulation::create(config);
  if (!sim) {
    std::fprintf(stderr, "%s\n", sim.error().c_str());
    std::abort();
  }
  return std::move(*sim);
}

void BM_TopologyUpdateWhileCutting(benchmark::State& state) {
  const int triangles = static_cast<int>(state.range(0));
  const Procedure procedure = *parse_procedure(kStrokes, "strokes");
  double median = 0.0, p99 = 0.0, per_tet = 0.0, removed = 0.0, refined = 0.0, steps = 0.0, list_builds = 0.0;
  for (auto _ : state) {
    state.PauseTiming();
    auto sim = simulation(triangles);
    const double tick_s = sim->config().tick_s();
    const auto ticks = static_cast<std::uint64_t>(std::llround(procedure.duration_s() / tick_s));
    std::array<double, kStageCount> budgets = default_stage_budgets_us(sim->config());
    FrameProfiler profiler(budgets, 16);
    state.ResumeTiming();
    double total_us = 0.0;
    std::int64_t removed_tets = 0, refined_tets = 0, cut_steps = 0;
    bool cut_in_flight = false;  // the collision step started at the last collision tick cuts
    for (std::uint64_t tick = 0; tick < ticks; ++tick) {
      const TickInput input = procedure_input(procedure, tick, tick_s);
      // A collision tick takes in the step started one collision tick before (its topology update,
      // timed on the thread that ran it): only those whose step cut reach the profiler.
      if (!sim->is_collision_tick(tick)) {
        sim->step(input, {});
        continue;
      }
      const bool collecting_a_cut = cut_in_flight;
      cut_in_flight = input.cut;
      if (!collecting_a_cut) {
        sim->step(input, {});
        continue;
      }
      sim->step(input, {}, &profiler);
      const ResectionStep& cut = sim->last_resection_step();
      removed_tets += cut.cut_tetrahedra + cut.hanging_tetrahedra + cut.chip_tetrahedra;
      refined_tets += cut.refined_tetrahedra;
      ++cut_steps;
    }
    sim->settle();
    list_builds = static_cast<double>(sim->resection().candidate_list_builds());
    const StageStatistics topology = profiler.statistics(Stage::kTopology);
    total_us = profiler.total_us(Stage::kTopology);
    median = topology.median_us;
    p99 = topology.p99_us;
    removed = static_cast<double>(removed_tets);
    refined = static_cast<double>(refined_tets);
    steps = static_cast<double>(cut_steps);
    per_tet = total_us / std::max(1.0, removed);
  }
  state.counters["topology_median_us"] = median;
  state.counters["topology_p99_us"] = p99;
  state.counters["us_per_removed_tet"] = per_tet;
  state.counters["removed_tets"] = removed;
  state.counters["refined_tets"] = refined;
  state.counters["cutting_steps"] = steps;
  state.counters["candidate_list_builds"] = list_builds;
}
BENCHMARK(BM_TopologyUpdateWhileCutting)->Arg(8640)->Arg(34560)->Iterations(1)->Unit(benchmark::kMillisecond);

/// Physics-stage median over one second with the tool withdrawn, after running `procedure_name`
/// (or on the uncut gland when empty).
struct GlandSize {
  std::size_t nodes = 0, stepped_nodes = 0, deferred_sum_nodes = 0, springs = 0;
};

double physics_median_us(int triangles, const char* procedure_name, double* remaining_fraction, GlandSize* size) {
  auto sim = simulation(triangles);
  const double tick_s = sim->config().tick_s();
  std::uint64_t tick = 0;
  if (procedure_name != nullptr) {
    const Procedure procedure = *builtin_procedure(procedure_name);
    const auto ticks = static_cast<std::uint64_t>(std::llround(procedure.duration_s() / tick_s));
    for (; tick < ticks; ++tick) sim->step(procedure_input(procedure, tick, tick_s), {});
  }
  FrameProfiler profiler(default_stage_budgets_us(sim->config()), 16);
  TickInput away;  // no tool: the gland alone
  for (std::uint64_t k = 0; k < 960; ++k, ++tick) sim->step(away, {}, &profiler);
  *remaining_fraction = sim->metrics().remaining_adenoma_fraction;
  size->nodes = sim->tissue().node_count();
  size->stepped_nodes = sim->tissue().stepped_node_count();
  size->deferred_sum_nodes = sim->tissue().deferred_sum_node_count();
  size->springs = sim->tissue().network().spring_count();
  return profiler.statistics(Stage::kPhysics).median_us;
}

void BM_PhysicsStepAfterTurp(benchmark::State& state) {
  double uncut = 0.0, cut = 0.0, fraction = 1.0, ignored = 1.0;
  GlandSize uncut_size, cut_size;
  for (auto _ : state) {
    uncut = physics_median_us(8640, nullptr, &ignored, &uncut_size);
    cut = physics_median_us(8640, "turp", &fraction, &cut_size);
  }
  state.counters["physics_median_uncut_us"] = uncut;
  state.counters["physics_median_after_turp_us"] = cut;
  state.counters["ratio"] = cut / uncut;
  state.counters["remaining_adenoma_fraction"] = fraction;
  state.counters["nodes_uncut"] = static_cast<double>(uncut_size.nodes);
  state.counters["nodes_after"] = static_cast<double>(cut_size.nodes);
  state.counters["stepped_nodes_uncut"] = static_cast<double>(uncut_size.stepped_nodes);
  state.counters["stepped_nodes_after"] = static_cast<double>(cut_size.stepped_nodes);
  state.counters["deferred_sum_nodes_after"] = static_cast<double>(cut_size.deferred_sum_nodes);
  state.counters["springs_uncut"] = static_cast<double>(uncut_size.springs);
  state.counters["springs_after"] = static_cast<double>(cut_size.springs);
}
BENCHMARK(BM_PhysicsStepAfterTurp)->Iterations(1)->Unit(benchmark::kSecond);

}  // namespace
}  // namespace resecto

BENCHMARK_MAIN();
