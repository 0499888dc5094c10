// The steady-state physics step allocates nothing: this binary replaces the global operator new and
// counts calls while the loop presses into the gland, steps run and candidates are refreshed.
#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <new>

#include "rtcore/anatomy/resectoscope.h"
#include "rtcore/scenes/indentation.h"

namespace {
std::atomic<bool> g_counting{false};
std::atomic<long> g_allocations{0};
}  // namespace

// These replacements pair malloc with free on purpose; GCC's mismatch warning sees only the names.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"
void* operator new(std::size_t size) {
  if (g_counting.load(std::memory_order_relaxed)) g_allocations.fetch_add(1, std::memory_order_relaxed);
  if (void* p = std::malloc(size == 0 ? 1 : size)) return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t size) { return operator new(size); }
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }
#pragma GCC diagnostic pop

namespace resecto {
namespace {

TEST(MassSpringAllocation, SteadyStateStepsAllocateNothing) {
  Result<ProstateTissueModel> model = build_prostate_tissue_model(generate_prostate(1296), generate_resectoscope().loop);
  ASSERT_TRUE(model) << model.error();
  for (TissueIntegrator integrator :
       {TissueIntegrator::kBoundedSymplectic, TissueIntegrator::kSubsteppedSymplectic, TissueIntegrator::kImplicitEuler}) {
    TissueConfig config;
    config.integrator = integrator;
    MassSpringTissue tissue(model->mesh, {}, config);
    const int part = tissue.tool().add_part(model->loop);
    tissue.tool().reset_pose(part, indentation_loop_pose(model->anatomy, model->loop, 0.0));
    auto run = [&](int from, int to) {
      for (int tick = from; tick < to; ++tick) {
        if (tick % 16 == 0) tissue.collision_step();
        tissue.tool().set_pose(part, indentation_loop_pose(model->anatomy, model->loop, 0.004 * std::min(1.0, tick / 100.0)));
        (void)tissue.physics_step(1.0 / 960.0);
      }
    };
    run(0, 32);  // warm-up: the first collision steps size the collider's buffers
    g_allocations = 0;
    g_counting = true;
    run(32, 160);
    tissue.apply({160, TissueParameter::kStiffness, 80.0});  // a live change at a tick boundary
    run(160, 200);
    g_counting = false;
    EXPECT_EQ(g_allocations.load(), 0) << "integrator " << static_cast<int>(integrator);
    EXPECT_GT(tissue.max_displacement_m(), 0.001) << "the loop pressed in, integrator " << static_cast<int>(integrator)
                                                << ", substeps " << tissue.last_substeps();
  }
}

}  // namespace
}  // namespace resecto
