// The steady-state physics step allocates nothing: RealtimeProbe (tests/support) counts the global
// operator new's calls while the loop presses into the gland, steps run and candidates are refreshed.
#include <gtest/gtest.h>

#include "rtcore/anatomy/resectoscope.h"
#include "rtcore/scenes/indentation.h"
#include "tests/support/realtime_probe.h"

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
    long allocations = 0;
    {
      testing::RealtimeProbe probe;
      run(32, 160);
      tissue.apply({160, TissueParameter::kStiffness, 80.0});  // a live change at a tick boundary
      run(160, 200);
      allocations = probe.allocations();
    }
    EXPECT_EQ(allocations, 0) << "integrator " << static_cast<int>(integrator);
    EXPECT_GT(tissue.max_displacement_m(), 0.001) << "the loop pressed in, integrator " << static_cast<int>(integrator)
                                                << ", substeps " << tissue.last_substeps();
  }
}

}  // namespace
}  // namespace resecto
