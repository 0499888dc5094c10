// Leaving resection's orphans out of the physics step (TissueConfig::skip_orphans) changes no bit:
// a gland cut and then pressed by the loop moves exactly as the same gland stepping every node.
#include <gtest/gtest.h>

#include <vector>

#include "rtcore/scenes/indentation.h"
#include "tests/support/gland_strokes.h"
#include "tests/support/same_bits.h"
#include "tests/support/tissue_models.h"

namespace resecto {
namespace {

using testing::same_bits;

TEST(OrphanSkipping, ACutGlandMovesBitForBitAsWhenEveryNodeIsStepped) {
  const ProstateTissueModel& model = tissue_model(1296);
  TissueConfig every_node_config;
  every_node_config.skip_orphans = false;
  MassSpringTissue skipping(model.mesh), every_node(model.mesh, {}, every_node_config);
  Resection cut_skipping(skipping), cut_every_node(every_node);
  cut_through_gland(cut_skipping, 12);
  cut_through_gland(cut_every_node, 12);
  skipping.refresh_stepped_nodes();
  every_node.refresh_stepped_nodes();

  std::size_t orphans = 0;
  for (std::uint32_t n = 0; n < skipping.node_count(); ++n) orphans += skipping.topology().valence(n) == 0 ? 1 : 0;
  ASSERT_GT(orphans, 20u) << "the strokes must leave orphans behind";
  EXPECT_LT(skipping.stepped_node_count(), skipping.node_count());
  EXPECT_GE(skipping.stepped_node_count(), skipping.node_count() - orphans);
  EXPECT_EQ(every_node.stepped_node_count(), every_node.node_count());

  // The loop presses in 3 mm, holds, and withdraws: the tissue moves and settles.
  const int loop_skipping = skipping.tool().add_part(model.loop), loop_every_node = every_node.tool().add_part(model.loop);
  const RigidPose pressed = indentation_loop_pose(model.anatomy, model.loop, 0.003);
  const RigidPose away = indentation_loop_pose(model.anatomy, model.loop, -0.02);
  double largest_speed = 0.0;
  for (int step = 0; step < 480; ++step) {
    const RigidPose& pose = step < 240 ? pressed : away;
    if (step % 16 == 0) {
      skipping.tool().set_pose(loop_skipping, pose);
      every_node.tool().set_pose(loop_every_node, pose);
      skipping.collision_step();
      every_node.collision_step();
    }
    (void)skipping.physics_step(1.0 / 960.0);
    (void)every_node.physics_step(1.0 / 960.0);
    for (const Vec3& v : skipping.velocities()) largest_speed = std::max(largest_speed, length(v));
    ASSERT_TRUE(same_bits(skipping.positions(), every_node.positions())) << "step " << step;
    ASSERT_TRUE(same_bits(skipping.velocities(), every_node.velocities())) << "step " << step;
    ASSERT_EQ(skipping.state_hash(), every_node.state_hash()) << "step " << step;
  }
  EXPECT_GT(largest_speed, 1e-3) << "the press must move the tissue";
}

}  // namespace
}  // namespace resecto
