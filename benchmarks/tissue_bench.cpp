// Tissue step costs on the 1296 .. 138240-triangle prostates, the loop pressed 3 mm into the left
// lobe: the physics step (960 Hz) and the collision step (refit + query + candidate update, 60 Hz),
// printed side by side, and the integrators compared at the default and the stiffest setting.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <map>
#include <memory>
#include <string>

#include "rtcore/anatomy/resectoscope.h"
#include "rtcore/base/quantile.h"
#include "rtcore/concurrency/loop_helper.h"
#include "rtcore/scenes/indentation.h"

namespace resecto {
namespace {

constexpr double kStepS = 1.0 / 960.0;

const ProstateTissueModel& model(int triangles) {
  static std::map<int, std::unique_ptr<ProstateTissueModel>> models;
  auto& slot = models[triangles];
  if (!slot) {
    Result<ProstateTissueModel> built = build_prostate_tissue_model(generate_prostate(triangles), generate_resectoscope().loop);
    if (!built) {
      std::fprintf(stderr, "%s\n", built.error().c_str());
      std::abort();
    }
    slot = std::make_unique<ProstateTissueModel>(std::move(*built));
  }
  return *slot;
}

double elapsed_us(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - start).count();
}

/// A tissue with the loop pressed `depth_m` into the lobe, settled for `settle_steps` steps or until
/// `budget_s` of wall time has passed (the steps taken are left in *steps_taken).
std::unique_ptr<MassSpringTissue> pressed_tissue(int triangles, const TissueParameters& parameters, const TissueConfig& config,
                                                 double depth_m = 0.003, int settle_steps = 480, double budget_s = 1e30,
                                                 int* steps_taken = nullptr) {
  const ProstateTissueModel& m = model(triangles);
  auto tissue = std::make_unique<MassSpringTissue>(m.mesh, parameters, config);
  const TriangleMesh& loop = m.loop;
  const int part = tissue->tool().add_part(loop);
  tissue->tool().reset_pose(part, indentation_loop_pose(m.anatomy, loop, 0.0));
  const auto start = std::chrono::steady_clock::now();
  int step = 0;
  for (; step < settle_steps && elapsed_us(start) < 1e6 * budget_s; ++step) {
    if (step % 16 == 0) tissue->collision_step();
    tissue->tool().set_pose(part, indentation_loop_pose(m.anatomy, loop, depth_m * std::min(1.0, (step + 1) / 320.0)));
    (void)tissue->physics_step(kStepS);
  }
  if (steps_taken != nullptr) *steps_taken = step;
  tissue->collision_step();
  return tissue;
}

struct Row {
  std::size_t nodes = 0, springs = 0, contacts = 0;
  std::vector<double> physics_us, collision_us;
};
/// The physics step's variants measured.
enum class Variant { kCertificates, kBruteForce, kWithHelper };
/// The rows of the tables, by triangle count: the physics step as the core runs it alone, with every
/// candidate point tested every step (brute force), or with its loops shared with a helper thread.
std::map<int, Row>& rows(Variant variant = Variant::kCertificates) {
  static std::map<int, Row> r[3];
  return r[static_cast<int>(variant)];
}

/// The physics step as the core runs it: a collision step (untimed) publishes fresh candidates every
/// 16 steps. Argument 1 is 0 for the brute-force contact (every candidate point tested every step),
/// the reference the clearance certificates are measured against.
void BM_PhysicsStep(benchmark::State& state) {
  const int triangles = static_cast<int>(state.range(0));
  const bool skipping = state.range(1) != 0;
  const bool helped = state.range(2) > 1;
  auto tissue = pressed_tissue(triangles, {}, {});
  tissue->tool().set_clearance_skipping(skipping);
  LoopHelper helper;
  if (helped) tissue->share_loops_with(&helper);
  Row& row = rows(helped ? Variant::kWithHelper : skipping ? Variant::kCertificates : Variant::kBruteForce)[triangles];
  row.nodes = tissue->node_count();
  row.springs = tissue->network().spring_count();
  row.contacts = static_cast<std::size_t>(tissue->tool().stats().pair_entries);
  const std::int64_t evaluated_before = tissue->tool().points_evaluated(), skipped_before = tissue->tool().points_skipped();
  int step = 0;
  for (auto _ : state) {
    if (++step % 16 == 0) {
      state.PauseTiming();
      tissue->collision_step();
      state.ResumeTiming();
    }
    const auto start = std::chrono::steady_clock::now();
    benchmark::DoNotOptimize(tissue->physics_step(kStepS));
    row.physics_us.push_back(elapsed_us(start));
  }
  state.counters["nodes"] = static_cast<double>(row.nodes);
  state.counters["springs"] = static_cast<double>(row.springs);
  const ToolContactStats& contact = tissue->tool().stats();
  state.counters["candidate_nodes"] = contact.tissue_nodes;
  state.counters["candidate_vertices"] = contact.tool_vertices;
  state.counters["penetrating"] = contact.penetrating;
  const auto evaluated = static_cast<double>(tissue->tool().points_evaluated() - evaluated_before);
  const auto skipped = static_cast<double>(tissue->tool().points_skipped() - skipped_before);
  state.counters["points_skipped"] = skipped / std::max(1.0, evaluated + skipped);
  if (helped) state.counters["helped_share"] = static_cast<double>(helper.chunks_helped()) / std::max(1.0, static_cast<double>(helper.chunks_offered()));
  state.SetLabel(std::string(skipping ? "clearance certificates" : "brute-force contact") + (helped ? ", with the helper thread" : ""));
  tissue->share_loops_with(nullptr);
}

void BM_CollisionStep(benchmark::State& state) {
  const int triangles = static_cast<int>(state.range(0));
  auto tissue = pressed_tissue(triangles, {}, {});
  Row& row = rows()[triangles];
  std::vector<double> refit_us, search_us;
  for (auto _ : state) {
    // The collision step's parts, timed apart as the core's profiler shows them (refit, query).
    const auto start = std::chrono::steady_clock::now();
    tissue->begin_collision_step();
    tissue->refit_surface_tree();
    const auto refitted = std::chrono::steady_clock::now();
    tissue->search_contact_candidates();
    tissue->end_collision_step();
    row.collision_us.push_back(elapsed_us(start));
    refit_us.push_back(std::chrono::duration<double, std::micro>(refitted - start).count());
    search_us.push_back(elapsed_us(refitted));
  }
  state.counters["refit_median_us"] = resecto::quantile(refit_us, 0.5);
  state.counters["search_median_us"] = resecto::quantile(search_us, 0.5);
  const ToolContactStats& stats = tissue->tool().stats();
  state.counters["candidate_pairs"] = stats.pair_entries;
  state.counters["pair_tests"] = stats.pair_tests;
  state.counters["tissue_leaves"] = stats.tissue_leaves;
  state.counters["tool_clusters"] = stats.tool_clusters;
  state.counters["candidate_nodes"] = stats.tissue_nodes;
  state.counters["candidate_vertices"] = stats.tool_vertices;
}

BENCHMARK(BM_PhysicsStep)
    ->ArgsProduct({{1296, 8640, 34560, 138240}, {1, 0}, {1}})
    ->ArgsProduct({{1296, 8640, 34560, 138240}, {1}, {2}})
    ->Unit(benchmark::kMicrosecond)
    ->MinTime(1.0);
BENCHMARK(BM_CollisionStep)->Arg(1296)->Arg(8640)->Arg(34560)->Arg(138240)->Unit(benchmark::kMicrosecond)->MinTime(1.0);

/// A live parameter change at a tick boundary (an instructor dragging a slider sends one a frame): what
/// it adds to the tick it lands in, on the pressed 8640 model.
void BM_ParameterChange(benchmark::State& state) {
  auto tissue = pressed_tissue(static_cast<int>(state.range(0)), {}, {});
  double stiffness_kpa = 40.0;
  for (auto _ : state) {
    stiffness_kpa = stiffness_kpa == 40.0 ? 41.0 : 40.0;
    tissue->apply({0, TissueParameter::kStiffness, stiffness_kpa});
  }
}
BENCHMARK(BM_ParameterChange)->Arg(8640)->Unit(benchmark::kMicrosecond)->MinTime(0.5);

/// What the locality numbering buys: the physics step with the nodes in the mesh's (TetGen's) order
/// and in locality order, at 8640 and 34560 triangles. Run with --benchmark_repetitions and
/// --benchmark_enable_random_interleaving so both orders see the same machine.
void BM_NodeOrder(benchmark::State& state) {
  TissueConfig config;
  config.locality_order = state.range(1) != 0;
  auto tissue = pressed_tissue(static_cast<int>(state.range(0)), {}, config);
  for (auto _ : state) benchmark::DoNotOptimize(tissue->physics_step(kStepS));
  state.SetLabel(config.locality_order ? "locality order" : "mesh order");
}
BENCHMARK(BM_NodeOrder)->Args({8640, 0})->Args({8640, 1})->Args({34560, 0})->Args({34560, 1})->Unit(benchmark::kMicrosecond)->MinTime(0.5);

/// The integrators on the 8640 model: cost of a step, and whether 1 s of pressing (then the timed
/// steps) at the default and the stiffest setting stays finite and bounded. The sub-stepped
/// integrator needs hundreds of sub-steps a step, so pressing is capped at 30 s of wall time
/// (counter settled_s: the simulated time reached) and it is timed over 5 steps, not 200.
constexpr double kSettleBudgetS = 30.0;
void BM_Integrator(benchmark::State& state) {
  const auto integrator = static_cast<TissueIntegrator>(state.range(0));
  const bool stiffest = state.range(1) != 0;
  TissueParameters p;
  if (stiffest) {
    (void)p.set(TissueParameter::kStiffness, tissue_parameter_spec(TissueParameter::kStiffness).max_value);
    (void)p.set(TissueParameter::kPenaltyStiffness, tissue_parameter_spec(TissueParameter::kPenaltyStiffness).max_value);
  }
  TissueConfig config;
  config.integrator = integrator;
  int settled_steps = 0;
  auto tissue = pressed_tissue(8640, p, config, 0.003, 960, kSettleBudgetS, &settled_steps);
  const bool finite = tissue->faults().non_finite_steps == 0;
  int substeps = 0, cg = 0;
  std::int64_t steps = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(tissue->physics_step(kStepS));
    substeps += tissue->last_substeps();
    cg += tissue->last_cg_iterations();
    ++steps;
  }
  state.counters["settled_s"] = settled_steps * kStepS;
  state.counters["finite_settled"] = finite ? 1 : 0;
  state.counters["finite_end"] = tissue->faults().non_finite_steps == 0 ? 1 : 0;
  state.counters["kinetic_J"] = tissue->kinetic_energy_j();
  state.counters["substeps"] = static_cast<double>(substeps) / static_cast<double>(steps);
  state.counters["cg_iterations"] = static_cast<double>(cg) / static_cast<double>(steps);
  state.SetLabel(std::string(integrator == TissueIntegrator::kBoundedSymplectic      ? "bounded-symplectic"
                             : integrator == TissueIntegrator::kSubsteppedSymplectic ? "substepped-symplectic"
                                                                                     : "implicit-euler-cg") +
                 (stiffest ? " stiffest" : " default"));
}
BENCHMARK(BM_Integrator)->Args({0, 0})->Args({0, 1})->Args({2, 0})->Args({2, 1})->Unit(benchmark::kMicrosecond)->Iterations(200);
BENCHMARK(BM_Integrator)->Args({1, 0})->Args({1, 1})->Unit(benchmark::kMicrosecond)->Iterations(5);

}  // namespace

/// The physics step's median as the core runs it against `other`'s, per size, and the ratio.
void print_physics_comparison(const char* title, const char* core_header, const char* other_header, Variant other) {
  std::printf("\n%s:\n%10s | %18s %18s | %8s\n", title, "triangles", core_header, other_header, "speed-up");
  for (const auto& [triangles, row] : rows()) {
    const auto found = rows(other).find(triangles);
    if (found == rows(other).end() || found->second.physics_us.empty() || row.physics_us.empty()) continue;
    const double core = quantile(row.physics_us, 0.5), compared = quantile(found->second.physics_us, 0.5);
    const double speed_up = other == Variant::kWithHelper ? core / compared : compared / core;
    std::printf("%10d | %18.1f %18.1f | %7.2fx\n", triangles, core, compared, speed_up);
  }
}

}  // namespace resecto

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  std::printf("\n%10s %8s %8s %10s | %18s %18s | %18s %18s\n", "triangles", "nodes", "springs", "cand.pairs", "physics median us",
              "physics p99 us", "collision median us", "collision p99 us");
  for (const auto& [triangles, row] : resecto::rows()) {
    std::printf("%10d %8zu %8zu %10zu | %18.1f %18.1f | %18.1f %18.1f\n", triangles, row.nodes, row.springs, row.contacts,
                resecto::quantile(row.physics_us, 0.5), resecto::quantile(row.physics_us, 0.99),
                resecto::quantile(row.collision_us, 0.5), resecto::quantile(row.collision_us, 0.99));
  }
  resecto::print_physics_comparison("physics step, contact by clearance certificates against brute force (every candidate point every step)",
                                    "certificates us", "brute force us", resecto::Variant::kBruteForce);
  resecto::print_physics_comparison("physics step alone and with its spring and node loops shared with a helper thread (same state bit for bit)",
                                    "alone us", "with helper us", resecto::Variant::kWithHelper);
  std::printf("budgets: physics step at 960 Hz within a third of a core = 347 us; collision step (on the collision thread, "
              "alongside the physics ticks) refit 15%% + query 45%% of the 16667 us collision period = 10000 us\n");
  return 0;
}
