// Temporal coherence (Collider::collide_sequence) against a fresh query and brute force at every
// frame: smooth 60 Hz motions of the resectoscope in the channel, jumps, a deforming tissue, and
// triangles removed and inserted between frames; and the slab bounds on their own.
#include "rtcore/collision/collide.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "scene.h"

namespace resecto {
namespace {


std::vector<TrianglePair> pairs_of(const Collider& collider) { return {collider.pairs().begin(), collider.pairs().end()}; }

struct Scene {
  ProstateModel prostate;
  TriangleMesh tool;
  SphereTree tissue_tree, tool_tree;
  explicit Scene(int triangles) : prostate(generate_prostate(triangles)) {
    tool = combined_resectoscope_mesh(generate_resectoscope());
    tissue_tree.build(prostate.surface);
    tool_tree.build(tool);
  }
};

constexpr CollisionMethod kMethods[] = {CollisionMethod::kToolField, CollisionMethod::kDualDescent};

TEST(CollideSequence, EveryFrameEqualsAFreshQueryAndBruteForce) {
  Scene scene(2816);
  for (const CollisionMethod method : kMethods) {
  Collider fresh, sequence;
  fresh.set_method(method);
  sequence.set_method(method);
  std::int64_t kept = 0, pairs = 0;
  for (int run = 0; run < 3; ++run) {
    sequence.reset_sequence();
    for (int f = 0; f < 90; ++f) {
      const RigidPose pose = channel_sweep_pose(f, 1.7 * run);
      ASSERT_TRUE(fresh.collide(scene.tissue_tree, scene.prostate.surface, scene.tool_tree, scene.tool, pose));
      ASSERT_TRUE(sequence.collide_sequence(scene.tissue_tree, scene.prostate.surface, scene.tool_tree, scene.tool, pose));
      const auto expected = collide_brute_force(scene.prostate.surface, scene.tool, pose);
      ASSERT_EQ(pairs_of(fresh), expected) << "run " << run << " frame " << f;
      ASSERT_EQ(pairs_of(sequence), expected) << "run " << run << " frame " << f;
      kept += sequence.stats().front_kept;
      pairs += static_cast<std::int64_t>(expected.size());
    }
  }
  EXPECT_GT(pairs, 1000) << "the sweep must press into the wall";
  EXPECT_GT(kept, 0) << "no certificate was ever reused";
  }
}

// Large jumps expire the certificates; standing still keeps them; exact either way.
TEST(CollideSequence, JumpsAndStandstillsStayExact) {
  Scene scene(1296);
  for (const CollisionMethod method : kMethods) {
  Collider sequence;
  sequence.set_method(method);
  std::mt19937_64 rng(3);
  for (int i = 0; i < 60; ++i) {
    const RigidPose pose = (i % 3 == 2) ? random_channel_pose(rng) : channel_sweep_pose(i, 0.4);
    for (int repeat = 0; repeat < 2; ++repeat) {
      ASSERT_TRUE(sequence.collide_sequence(scene.tissue_tree, scene.prostate.surface, scene.tool_tree, scene.tool, pose));
      ASSERT_EQ(pairs_of(sequence), collide_brute_force(scene.prostate.surface, scene.tool, pose)) << "step " << i;
      if (repeat == 1) {
        // Standing still: only the leaf pairs whose bounds meet (and pairs apart by less than the
        // rounding slack) are walked again.
        EXPECT_LE(sequence.stats().front_renewed, sequence.stats().leaf_pairs + sequence.stats().front_renewed / 100)
            << "step " << i;
      }
    }
  }
  }
}

// The tissue deforms between frames (its travel passed in) and loses and regains triangles (the
// tree's structure changes, so the front starts afresh): still brute force at every frame.
TEST(CollideSequence, FollowsDeformationAndCutting) {
  Scene scene(2816);
  TriangleMesh& surface = scene.prostate.surface;
  const std::vector<Vec3> rest = surface.positions;
  Collider sequence, dual;
  dual.set_method(CollisionMethod::kDualDescent);
  double travel = 0.0;
  std::vector<Vec3> previous = rest;
  std::vector<std::uint32_t> removed;
  std::mt19937_64 rng(11);
  for (int f = 0; f < 80; ++f) {
    const double amplitude = 0.0006 * std::sin(0.15 * f);  // up to 0.6 mm, 0.09 mm a frame at most
    double moved = 0.0;
    for (std::size_t v = 0; v < rest.size(); ++v) {
      const Vec3& p = rest[v];
      surface.positions[v] = p + amplitude * Vec3(std::sin(180 * p.z), std::cos(150 * p.x), std::sin(120 * p.y));
      moved = std::max(moved, length(surface.positions[v] - previous[v]));
    }
    previous = surface.positions;
    travel += moved;
    scene.tissue_tree.refit(surface);
    if (f % 10 == 9) {
      // Cut: remove a few triangles, put back the ones removed before.
      for (const std::uint32_t t : removed) scene.tissue_tree.insert_triangle(surface, t);
      removed.clear();
      for (int k = 0; k < 20; ++k) {
        const auto t = static_cast<std::uint32_t>(rng() % surface.triangle_count());
        if (scene.tissue_tree.first_leaf_of_triangle(t) == SphereTree::kNoNode) continue;
        scene.tissue_tree.remove_triangle(t);
        removed.push_back(t);
      }
    }
    const RigidPose pose = channel_sweep_pose(f, 2.5);
    ASSERT_TRUE(sequence.collide_sequence(scene.tissue_tree, surface, scene.tool_tree, scene.tool, pose, travel));
    ASSERT_TRUE(dual.collide_sequence(scene.tissue_tree, surface, scene.tool_tree, scene.tool, pose, travel));
    auto expected = collide_brute_force(surface, scene.tool, pose);
    std::erase_if(expected, [&](const TrianglePair& p) {
      return scene.tissue_tree.first_leaf_of_triangle(p.tissue) == SphereTree::kNoNode;
    });
    ASSERT_EQ(pairs_of(sequence), expected) << "frame " << f << " (field)";
    ASSERT_EQ(pairs_of(dual), expected) << "frame " << f << " (dual descent)";
  }
  testing::expect_slabs_cover(scene.tissue_tree, surface);
}

// Slabs on and off give the dual descent the same pairs; the slab leaf lists are a subset of the
// spheres' lists.
TEST(CollideSequence, SlabsChangeTheWorkNotThePairs) {
  Scene scene(1296);
  Collider with, without;
  with.set_method(CollisionMethod::kDualDescent);
  without.set_method(CollisionMethod::kDualDescent);
  without.set_slabs(false);
  std::mt19937_64 rng(8);
  std::int64_t with_tests = 0, without_tests = 0;
  for (int i = 0; i < 200; ++i) {
    const RigidPose pose = random_channel_pose(rng);
    ASSERT_TRUE(with.collide(scene.tissue_tree, scene.prostate.surface, scene.tool_tree, scene.tool, pose));
    ASSERT_TRUE(without.collide(scene.tissue_tree, scene.prostate.surface, scene.tool_tree, scene.tool, pose));
    ASSERT_EQ(pairs_of(with), pairs_of(without)) << "pose " << i;
    std::vector<std::int32_t> a(with.tissue_leaves().begin(), with.tissue_leaves().end());
    std::vector<std::int32_t> b(without.tissue_leaves().begin(), without.tissue_leaves().end());
    std::sort(a.begin(), a.end());
    std::sort(b.begin(), b.end());
    ASSERT_TRUE(std::includes(b.begin(), b.end(), a.begin(), a.end())) << "pose " << i;
    with_tests += with.stats().sphere_tests;
    without_tests += without.stats().sphere_tests;
  }
  EXPECT_LT(with_tests, without_tests);
  testing::expect_slabs_cover(scene.tissue_tree, scene.prostate.surface);
  testing::expect_slabs_cover(scene.tool_tree, scene.tool);
}

}  // namespace
}  // namespace resecto

namespace resecto {
namespace {

// A tree built without slabs (the contact's surface tree) refits and answers on its spheres alone:
// the same pairs as brute force, fresh and in a sequence, after deformation.
TEST(CollideSequence, TreesWithoutSlabsUseTheSpheres) {
  ProstateModel gland = generate_prostate(1296);
  TriangleMesh& surface = gland.surface;
  const TriangleMesh tool = combined_resectoscope_mesh(generate_resectoscope());
  SphereTree tissue_tree, tool_tree;
  tissue_tree.set_slabs(false);
  tissue_tree.build(surface);
  tool_tree.build(tool);
  EXPECT_FALSE(tissue_tree.has_slabs());
  EXPECT_TRUE(tool_tree.has_slabs());
  const std::vector<Vec3> rest = surface.positions;
  for (const CollisionMethod method : kMethods) {
  Collider fresh, sequence;
  fresh.set_method(method);
  sequence.set_method(method);
  for (int f = 0; f < 40; ++f) {
    for (std::size_t v = 0; v < rest.size(); ++v) {
      const Vec3& p = rest[v];
      surface.positions[v] = p + 0.0004 * std::sin(0.2 * f) * Vec3(std::sin(150 * p.z), std::cos(120 * p.x), 0.0);
    }
    tissue_tree.refit(surface);
    const RigidPose pose = channel_sweep_pose(f, 0.9);
    const auto expected = collide_brute_force(surface, tool, pose);
    ASSERT_TRUE(fresh.collide(tissue_tree, surface, tool_tree, tool, pose));
    ASSERT_TRUE(sequence.collide_sequence(tissue_tree, surface, tool_tree, tool, pose, 0.0004 * f));
    ASSERT_EQ(pairs_of(fresh), expected) << "frame " << f;
    ASSERT_EQ(pairs_of(sequence), expected) << "frame " << f;
  }
  }
  testing::expect_tree_invariants(tissue_tree);
}

}  // namespace
}  // namespace resecto
