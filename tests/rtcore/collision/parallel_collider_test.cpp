// A query shared by two threads gives one Collider's pairs, and brute force's, whoever claims which
// subtree: both methods, random channel poses, a tree reshaped by removals and insertions, a 60 Hz
// sequence with each thread's front, and warm queries that allocate nothing.
#include "rtcore/collision/parallel_collider.h"

#include <gtest/gtest.h>

#include <random>
#include <vector>

#include "scene.h"
#include "tests/support/realtime_probe.h"

namespace resecto {
namespace {

struct Gland {
  ProstateModel prostate = generate_prostate(2816);
  TriangleMesh tool = combined_resectoscope_mesh(generate_resectoscope());
  SphereTree tissue_tree, tool_tree;
  Gland() {
    tissue_tree.build(prostate.surface);
    tool_tree.build(tool);
  }
};

std::vector<TrianglePair> pairs_of(std::span<const TrianglePair> pairs) { return {pairs.begin(), pairs.end()}; }

// `poses` random channel poses: the shared query's pairs equal one Collider's, and brute force's
// every `brute_every` poses.
void expect_one_colliders_pairs(const Gland& gland, CollisionMethod method, int threads, int poses, int brute_every) {
  ParallelCollider shared(threads);
  shared.set_method(method);
  Collider alone;
  alone.set_method(method);
  std::mt19937_64 rng(23);
  int with_pairs = 0;
  for (int i = 0; i < poses; ++i) {
    const RigidPose pose = random_channel_pose(rng);
    ASSERT_TRUE(shared.collide(gland.tissue_tree, gland.prostate.surface, gland.tool_tree, gland.tool, pose));
    ASSERT_TRUE(alone.collide(gland.tissue_tree, gland.prostate.surface, gland.tool_tree, gland.tool, pose));
    ASSERT_EQ(pairs_of(shared.pairs()), pairs_of(alone.pairs())) << "pose " << i << ", " << threads << " threads";
    EXPECT_GT(shared.stats().sphere_tests, 0);
    if (i % brute_every == 0) {
      ASSERT_EQ(pairs_of(shared.pairs()), collide_brute_force(gland.prostate.surface, gland.tool, pose)) << "pose " << i;
    }
    with_pairs += shared.pairs().empty() ? 0 : 1;
  }
  EXPECT_GT(with_pairs, poses / 2) << "the poses press the tool into the wall";
}

TEST(ParallelCollider, TwoThreadsGiveOneCollidersPairsWithTheField) {
  const Gland gland;
  expect_one_colliders_pairs(gland, CollisionMethod::kToolField, 2, 400, 20);
}

TEST(ParallelCollider, TwoThreadsGiveOneCollidersPairsWithTheDualDescent) {
  const Gland gland;
  expect_one_colliders_pairs(gland, CollisionMethod::kDualDescent, 2, 200, 20);
}

TEST(ParallelCollider, OneThreadGivesOneCollidersPairs) {
  const Gland gland;
  expect_one_colliders_pairs(gland, CollisionMethod::kToolField, 1, 100, 20);
}

TEST(ParallelCollider, ATreeReshapedByRemovalsAndInsertionsIsSplitAsWell) {
  // After edits the nodes are no longer numbered depth first: the split follows the links.
  Gland gland;
  std::mt19937_64 rng(5);
  std::uniform_int_distribution<std::uint32_t> pick(0, static_cast<std::uint32_t>(gland.prostate.surface.triangle_count() - 1));
  for (int edit = 0; edit < 300; ++edit) {
    const std::uint32_t t = pick(rng);
    gland.tissue_tree.remove_triangle(t);
    gland.tissue_tree.insert_triangle(gland.prostate.surface, t);
  }
  testing::expect_tree_invariants(gland.tissue_tree);
  expect_one_colliders_pairs(gland, CollisionMethod::kToolField, 2, 100, 10);
}

// A 60 Hz sweep along the channel wall, with the tissue's tree edited halfway (its structure then
// changes and both fronts start afresh): every frame's pairs equal a fresh query's, with one thread
// and with two (the helper spinning, or asleep and late), and brute force's now and then.
void expect_sequence_as_fresh_queries(CollisionMethod method, int threads) {
  Gland gland;
  ParallelCollider shared(threads);
  shared.set_method(method);
  Collider fresh;
  fresh.set_method(method);
  std::int64_t kept = 0;
  for (int f = 0; f < 120; ++f) {
    if (f == 60) {
      for (std::uint32_t t = 0; t < gland.prostate.surface.triangle_count(); t += 7) {
        gland.tissue_tree.remove_triangle(t);
        gland.tissue_tree.insert_triangle(gland.prostate.surface, t);
      }
    }
    const RigidPose pose = channel_sweep_pose(f, 0.4);
    ASSERT_TRUE(shared.collide_sequence(gland.tissue_tree, gland.prostate.surface, gland.tool_tree, gland.tool, pose));
    ASSERT_TRUE(fresh.collide(gland.tissue_tree, gland.prostate.surface, gland.tool_tree, gland.tool, pose));
    ASSERT_EQ(pairs_of(shared.pairs()), pairs_of(fresh.pairs())) << "frame " << f << ", " << threads << " threads";
    if (f % 15 == 0) {
      ASSERT_EQ(pairs_of(shared.pairs()), collide_brute_force(gland.prostate.surface, gland.tool, pose)) << "frame " << f;
    }
    kept += shared.stats().front_kept;
    // Every other frame finds the helper asleep, so the caller's thread may run both halves: each
    // half's front stays with its Collider whichever thread ran it.
    if (f % 2 == 1) shared.release_helper();
  }
  EXPECT_GT(kept, 0) << "the fronts carry certificates from frame to frame";
}

TEST(ParallelCollider, TwoThreadsFollowASequenceAsFreshQueriesDo) {
  expect_sequence_as_fresh_queries(CollisionMethod::kToolField, 2);
  expect_sequence_as_fresh_queries(CollisionMethod::kDualDescent, 2);
}

TEST(ParallelCollider, OneThreadFollowsASequenceAsFreshQueriesDo) {
  expect_sequence_as_fresh_queries(CollisionMethod::kToolField, 1);
}

TEST(ParallelCollider, WarmQueriesAllocateNothing) {
  const Gland gland;
  ParallelCollider shared(2);
  shared.prepare_tool(gland.tool);
  const auto run = [&] {
    shared.reset_sequence();
    for (int f = 0; f < 60; ++f) {
      ASSERT_TRUE(shared.collide(gland.tissue_tree, gland.prostate.surface, gland.tool_tree, gland.tool, channel_sweep_pose(f, 0.7)));
      ASSERT_TRUE(shared.collide_sequence(gland.tissue_tree, gland.prostate.surface, gland.tool_tree, gland.tool, channel_sweep_pose(f, 0.7)));
    }
  };
  run();  // warm-up: the buffers take their sizes
  long allocations = 0;
  {
    testing::RealtimeProbe probe;
    run();
    allocations = probe.allocations();
  }
  EXPECT_EQ(allocations, 0);
}

}  // namespace
}  // namespace resecto
