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

}  // namespace
}  // namespace resecto
