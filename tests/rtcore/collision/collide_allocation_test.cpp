// Queries allocate nothing once a collider has seen its trees and tool: both methods, fresh and as
// a sequence (RealtimeProbe counts the global operator new's calls).
#include <gtest/gtest.h>

#include "rtcore/collision/collide.h"
#include "scene.h"
#include "tests/support/realtime_probe.h"

namespace resecto {
namespace {

TEST(CollideAllocation, WarmQueriesAllocateNothing) {
  ProstateModel gland = generate_prostate(2816);
  const TriangleMesh tool = combined_resectoscope_mesh(generate_resectoscope());
  SphereTree tissue_tree, tool_tree;
  tissue_tree.build(gland.surface);
  tool_tree.build(tool);
  for (const CollisionMethod method : {CollisionMethod::kToolField, CollisionMethod::kDualDescent}) {
    Collider fresh, sequence;
    fresh.set_method(method);
    sequence.set_method(method);
    std::int64_t pairs = 0;
    const auto run = [&](int from, int to) {
      for (int f = from; f < to; ++f) {
        const RigidPose pose = channel_sweep_pose(f, 1.1);
        ASSERT_TRUE(fresh.collide(tissue_tree, gland.surface, tool_tree, tool, pose));
        ASSERT_TRUE(sequence.collide_sequence(tissue_tree, gland.surface, tool_tree, tool, pose));
        pairs += static_cast<std::int64_t>(fresh.pairs().size());
      }
    };
    run(0, 90);  // warm-up: the field, the buffers and the front take their sizes
    long allocations = 0;
    {
      testing::RealtimeProbe probe;
      run(0, 90);
      allocations = probe.allocations();
    }
    EXPECT_EQ(allocations, 0) << (method == CollisionMethod::kToolField ? "field" : "dual descent");
    EXPECT_GT(pairs, 1000) << "the sweep presses into the wall";
  }
}

// A rebuild runs in the core's collision job beside the physics (and on the core's thread in a batch
// run): within the room reserved, it and the refit after it allocate nothing either.
TEST(CollideAllocation, RebuildWithinTheReservedRoomAllocatesNothing) {
  ProstateModel gland = generate_prostate(2816);
  SphereTree tree;
  tree.set_slabs(false);
  tree.reserve(4 * static_cast<std::int32_t>(gland.surface.triangle_count()), gland.surface.triangle_count());
  tree.build(gland.surface);
  for (std::uint32_t t = 0; t < gland.surface.triangle_count(); t += 5) tree.remove_triangle(t);
  tree.rebuild(gland.surface);  // the scratch takes its size
  tree.refit(gland.surface);
  const std::int32_t leaves = tree.leaf_count();
  long allocations = 0;
  {
    testing::RealtimeProbe probe;
    tree.rebuild(gland.surface);
    tree.refit(gland.surface);
    allocations = probe.allocations();
  }
  EXPECT_EQ(allocations, 0);
  EXPECT_EQ(tree.leaf_count(), leaves);
  EXPECT_EQ(tree.live_node_count(), 2 * leaves - 1);
}

}  // namespace
}  // namespace resecto
