// Resection through the core: the built-in procedures cut, mass is conserved by region after every
// collision step, and the remaining surface stays a valid closed surface enclosing the remaining volume.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "rtcore/mesh/mesh_validation.h"
#include "tests/support/procedure_input.h"

namespace resecto {
namespace {

constexpr auto kCapsule = static_cast<std::size_t>(TissueRegion::kCapsule);
constexpr auto kAdenoma = static_cast<std::size_t>(TissueRegion::kAdenoma);

struct RunCheck {
  double worst_conservation = 0.0;  // relative, over regions and collision steps
  std::uint64_t collision_steps = 0;
};

/// Runs `procedure` through the core, checking initial = remaining + removed per region after every
/// collision step against a fresh sum over the live tetrahedra.
RunCheck run_checked(Simulation& sim, const Procedure& procedure) {
  RunCheck check;
  const double tick_s = sim.config().tick_s();
  const auto ticks = static_cast<std::uint64_t>(std::llround(procedure.duration_s() / tick_s));
  for (std::uint64_t tick = 0; tick < ticks; ++tick) {
    sim.step(procedure_input(procedure, tick, tick_s), {});
    if (!sim.is_collision_tick(tick)) continue;
    ++check.collision_steps;
    const ResectionStats& stats = sim.resection().stats();
    const RegionVolumes remaining = sim.resection().remaining_m3();
    for (std::size_t r : {kCapsule, kAdenoma}) {
      const double error = std::abs(stats.initial_m3[r] - (remaining[r] + stats.removed_m3[r])) / stats.initial_m3[r];
      check.worst_conservation = std::max(check.worst_conservation, error);
    }
  }
  return check;
}

void expect_valid_surface(const Simulation& sim, const char* what) {
  const TriangleMesh surface = sim.tissue().live_surface(true);
  Result<SurfaceReport> report = validate_closed_surface(surface);
  ASSERT_TRUE(report) << what << ": " << report.error();
  const RegionVolumes remaining = sim.resection().remaining_m3();
  const double volume = remaining[kCapsule] + remaining[kAdenoma];
  EXPECT_NEAR(report->volume_m3, volume, 1e-9 * volume) << what;
}

TEST(Resection, DemoCutsConservesMassAndKeepsAValidSurface) {
  SimulationConfig config;
  config.prostate_triangles = 1296;
  auto sim = Simulation::create(config);
  ASSERT_TRUE(sim) << sim.error();
  Result<Procedure> demo = builtin_procedure("demo");
  ASSERT_TRUE(demo);
  const RunCheck check = run_checked(**sim, *demo);
  const ProcedureMetrics& m = (*sim)->metrics();
  std::printf("demo 1296: resected %.3f g (adenoma %.3f, capsule %.3f), chips %llu (%.3f g), cuts %llu, refined %llu, refusals %llu, "
              "displacement %.2f mm, worst conservation %.2e\n",
              m.resected_total_g, m.resected_adenoma_g, m.resected_capsule_g, static_cast<unsigned long long>(m.chips), m.chips_g,
              static_cast<unsigned long long>(m.cuts), static_cast<unsigned long long>(m.refined_tetrahedra),
              static_cast<unsigned long long>(m.topology_refusals), m.max_tissue_displacement_mm, check.worst_conservation);
  EXPECT_GT(m.resected_adenoma_g, 0.1);
  EXPECT_GE(m.cuts, 1u);
  EXPECT_EQ(m.perforations, 0u);
  EXPECT_EQ(m.non_finite_steps, 0u);
  EXPECT_LT(check.worst_conservation, 1e-12);
  expect_valid_surface(**sim, "after demo");
}

}  // namespace
}  // namespace resecto
