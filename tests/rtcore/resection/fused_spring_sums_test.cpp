// Summing the spring forces inside the spring pass (TissueConfig::fuse_spring_sums,
// spring_sum_schedule.h) changes no bit: a gland cut by the loop (refinement's late springs defer
// some groups) and then pressed moves exactly as the same gland summed in a pass of its own, on one
// thread and with the loop helper taking chunks from the other end.
#include <gtest/gtest.h>

#include <vector>

#include "rtcore/concurrency/loop_helper.h"
#include "rtcore/scenes/indentation.h"
#include "tests/support/gland_strokes.h"
#include "tests/support/same_bits.h"
#include "tests/support/tissue_models.h"

namespace resecto {
namespace {

using testing::same_bits;

TEST(FusedSpringSums, ACutGlandMovesBitForBitAsWithASeparateSumPassOnOneThreadOrTwo) {
  const ProstateTissueModel& model = tissue_model(8640);
  TissueConfig separate_config;
  separate_config.fuse_spring_sums = false;
  MassSpringTissue fused(model.mesh), separate(model.mesh, {}, separate_config), helped(model.mesh);
  LoopHelper helper;
  helped.share_loops_with(&helper);
  for (MassSpringTissue* tissue : {&fused, &separate, &helped}) {
    Resection resection(*tissue);
    cut_through_gland(resection, 12);
    tissue->refresh_stepped_nodes();
  }
  ASSERT_GT(fused.deferred_sum_node_count(), 0u) << "refinement's springs must defer some groups";
  ASSERT_LT(fused.deferred_sum_node_count(), fused.stepped_node_count() / 2);

  const int loop_fused = fused.tool().add_part(model.loop), loop_separate = separate.tool().add_part(model.loop);
  const int loop_helped = helped.tool().add_part(model.loop);
  const RigidPose pressed = indentation_loop_pose(model.anatomy, model.loop, 0.003);
  const RigidPose away = indentation_loop_pose(model.anatomy, model.loop, -0.02);
  double largest_speed = 0.0;
  for (int step = 0; step < 320; ++step) {
    const RigidPose& pose = step < 160 ? pressed : away;
    if (step % 16 == 0) {
      fused.tool().set_pose(loop_fused, pose);
      separate.tool().set_pose(loop_separate, pose);
      helped.tool().set_pose(loop_helped, pose);
      fused.collision_step();
      separate.collision_step();
      helped.collision_step();
    }
    (void)fused.physics_step(1.0 / 960.0);
    (void)separate.physics_step(1.0 / 960.0);
    helper.call_in();
    (void)helped.physics_step(1.0 / 960.0);
    helper.send_home();
    for (const Vec3& v : fused.velocities()) largest_speed = std::max(largest_speed, length(v));
    ASSERT_TRUE(same_bits(fused.positions(), separate.positions())) << "step " << step;
    ASSERT_TRUE(same_bits(fused.velocities(), separate.velocities())) << "step " << step;
    ASSERT_TRUE(same_bits(helped.positions(), separate.positions())) << "step " << step;
    ASSERT_TRUE(same_bits(helped.velocities(), separate.velocities())) << "step " << step;
    ASSERT_EQ(fused.state_hash(), separate.state_hash()) << "step " << step;
  }
  EXPECT_GT(largest_speed, 1e-3) << "the press must move the tissue";
  EXPECT_GT(helper.chunks_helped(), 0u) << "the helper must have taken part";
}

}  // namespace
}  // namespace resecto
