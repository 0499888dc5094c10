// Both query methods (the tool field and the paper's dual descent) against brute force: the
// procedural gland and resectoscope over random poses in the channel, random triangle soups full of
// touching and coplanar faces, and a deformed gland.
#include "rtcore/collision/collide.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <set>

#include "scene.h"

namespace resecto {
namespace {


std::vector<TrianglePair> pairs_of(const Collider& collider) {
  return {collider.pairs().begin(), collider.pairs().end()};
}

constexpr CollisionMethod kMethods[] = {CollisionMethod::kToolField, CollisionMethod::kDualDescent};

Collider collider_using(CollisionMethod method) {
  Collider collider;
  collider.set_method(method);
  return collider;
}

// L1 and L2 hold each leaf once, and every pair's triangles have a leaf in them (the tool's in L2
// only for the dual descent; the field method lists no tool leaf).
void expect_leaf_lists(const Collider& collider, const SphereTree& tissue_tree, const SphereTree& tool_tree) {
  std::set<std::int32_t> l1(collider.tissue_leaves().begin(), collider.tissue_leaves().end());
  std::set<std::int32_t> l2(collider.tool_leaves().begin(), collider.tool_leaves().end());
  ASSERT_EQ(l1.size(), collider.tissue_leaves().size()) << "a tissue leaf is listed twice";
  ASSERT_EQ(l2.size(), collider.tool_leaves().size()) << "a tool leaf is listed twice";
  std::set<std::uint32_t> l1_triangles;
  std::set<std::uint32_t> l2_triangles;
  for (std::int32_t n : l1) {
    ASSERT_TRUE(tissue_tree.is_leaf(n));
    l1_triangles.insert(tissue_tree.pieces()[n].triangle);
  }
  for (std::int32_t n : l2) {
    ASSERT_TRUE(tool_tree.is_leaf(n));
    l2_triangles.insert(tool_tree.pieces()[n].triangle);
  }
  const bool dual = collider.method() == CollisionMethod::kDualDescent;
  if (!dual) {
    ASSERT_TRUE(l2.empty());
  }
  for (const TrianglePair& p : collider.pairs()) {
    ASSERT_TRUE(l1_triangles.count(p.tissue)) << "tissue triangle " << p.tissue << " has no leaf in L1";
    if (dual) {
      ASSERT_TRUE(l2_triangles.count(p.tool)) << "tool triangle " << p.tool << " has no leaf in L2";
    }
  }
}

struct ProstateScene {
  ProstateModel prostate;
  TriangleMesh tool;
  SphereTree tissue_tree;
  SphereTree tool_tree;
  explicit ProstateScene(int triangles, double slice_aspect = SphereTree::kSliceAspect)
      : prostate(generate_prostate(triangles)) {
    tool = combined_resectoscope_mesh(generate_resectoscope());
    tissue_tree.set_slice_aspect(slice_aspect);
    tool_tree.set_slice_aspect(slice_aspect);
    tissue_tree.build(prostate.surface);
    tool_tree.build(tool);
  }
};

// `poses` random channel poses: pairs equal brute force; the leaf lists checked every few poses.
void expect_brute_force_over_poses(const ProstateScene& scene, std::uint64_t seed, int poses, int list_every) {
  for (const CollisionMethod method : kMethods) {
    Collider collider = collider_using(method);
    std::mt19937_64 rng(seed);
    for (int i = 0; i < poses; ++i) {
      const RigidPose pose = random_channel_pose(rng);
      ASSERT_TRUE(collider.collide(scene.tissue_tree, scene.prostate.surface, scene.tool_tree, scene.tool, pose));
      ASSERT_EQ(pairs_of(collider), collide_brute_force(scene.prostate.surface, scene.tool, pose))
          << "pose " << i << (method == CollisionMethod::kToolField ? " (field)" : " (dual descent)");
      if (i % list_every == 0) expect_leaf_lists(collider, scene.tissue_tree, scene.tool_tree);
    }
  }
}

TEST(Collide, EqualsBruteForceOnTheGlandOverThousandsOfPoses) {
  ProstateScene scene(1296);
  Collider field = collider_using(CollisionMethod::kToolField);
  Collider dual = collider_using(CollisionMethod::kDualDescent);
  std::mt19937_64 rng(7);
  std::int64_t total_pairs = 0;
  int poses_with_pairs = 0;
  const int poses = 2000;
  for (int i = 0; i < poses; ++i) {
    const RigidPose pose = random_channel_pose(rng);
    ASSERT_TRUE(field.collide(scene.tissue_tree, scene.prostate.surface, scene.tool_tree, scene.tool, pose));
    ASSERT_TRUE(dual.collide(scene.tissue_tree, scene.prostate.surface, scene.tool_tree, scene.tool, pose));
    const auto expected = collide_brute_force(scene.prostate.surface, scene.tool, pose);
    ASSERT_EQ(pairs_of(field), expected) << "pose " << i << " (field)";
    ASSERT_EQ(pairs_of(dual), expected) << "pose " << i << " (dual descent)";
    if (i % 50 == 0) {
      expect_leaf_lists(field, scene.tissue_tree, scene.tool_tree);
      expect_leaf_lists(dual, scene.tissue_tree, scene.tool_tree);
    }
    total_pairs += static_cast<std::int64_t>(expected.size());
    poses_with_pairs += expected.empty() ? 0 : 1;
  }
  // The poses must actually press the tool into the wall most of the time.
  EXPECT_GT(poses_with_pairs, poses / 2);
  EXPECT_GT(total_pairs, 10 * poses);
}

TEST(Collide, LeafListsAloneAreTheSameListsWithoutTheTriangleTests) {
  // The contact response reads only L1 and L2: without the pairs the walk lists the same leaves in
  // the same order and tests no triangle.
  ProstateScene scene(1296);
  for (const CollisionMethod method : kMethods) {
    Collider with_pairs = collider_using(method), lists_only = collider_using(method);
    lists_only.set_pairs_wanted(false);
    std::mt19937_64 rng(11);
    for (int i = 0; i < 300; ++i) {
      const RigidPose pose = random_channel_pose(rng);
      ASSERT_TRUE(with_pairs.collide(scene.tissue_tree, scene.prostate.surface, scene.tool_tree, scene.tool, pose));
      ASSERT_TRUE(lists_only.collide(scene.tissue_tree, scene.prostate.surface, scene.tool_tree, scene.tool, pose));
      const auto l1 = with_pairs.tissue_leaves(), l2 = with_pairs.tool_leaves();
      ASSERT_TRUE(std::equal(l1.begin(), l1.end(), lists_only.tissue_leaves().begin(), lists_only.tissue_leaves().end())) << "pose " << i;
      ASSERT_TRUE(std::equal(l2.begin(), l2.end(), lists_only.tool_leaves().begin(), lists_only.tool_leaves().end())) << "pose " << i;
      EXPECT_TRUE(lists_only.pairs().empty());
      EXPECT_EQ(lists_only.stats().triangle_tests, 0);
    }
  }
}

// Slabs as wide as long cut most tissue triangles too: a triangle pair then meets through several
// leaf pairs on one side or both, and must still come out once (first meeting slab, or the table).
TEST(Collide, EqualsBruteForceWhenBothTreesAreSlicedFinely) {
  ProstateScene scene(1296, 1.0);
  ASSERT_GT(scene.tissue_tree.leaf_count(), static_cast<std::int32_t>(scene.prostate.surface.triangle_count()));
  expect_brute_force_over_poses(scene, 17, 300, 20);
}

TEST(Collide, EqualsBruteForceOnALargerGlandWithTheLoopPressedIn) {
  ProstateScene scene(8640);
  expect_brute_force_over_poses(scene, 11, 60, 1);
}

// Triangles on a coarse integer grid: shared vertices, shared edges, coplanar overlaps and pure
// touching are everywhere. Poses are exact (quarter turns, integer shifts) so nothing is rounded.
TEST(Collide, EqualsBruteForceOnTouchingAndCoplanarSoups) {
  std::mt19937_64 rng(3);
  std::uniform_int_distribution<int> grid(0, 6);
  Collider field = collider_using(CollisionMethod::kToolField);
  Collider dual = collider_using(CollisionMethod::kDualDescent);
  std::int64_t total = 0;
  for (int trial = 0; trial < 300; ++trial) {
    const auto soup = [&](int triangles) {
      TriangleMesh mesh;
      for (int t = 0; t < triangles; ++t) {
        const auto base = static_cast<std::uint32_t>(mesh.positions.size());
        for (int k = 0; k < 3; ++k) {
          mesh.positions.push_back(Vec3(grid(rng), grid(rng), trial % 3 == 0 ? 0 : grid(rng)));
        }
        if (cross(mesh.positions[base + 1] - mesh.positions[base], mesh.positions[base + 2] - mesh.positions[base]) ==
            Vec3(0.0)) {
          mesh.positions[base + 2] += Vec3(1, 2, trial % 3 == 0 ? 0 : 3);  // keep some area
        }
        mesh.triangles.push_back({base, base + 1, base + 2});
      }
      // Reuse vertices across triangles: shared-vertex configurations within and across soups.
      for (Triangle& tri : mesh.triangles) {
        if (grid(rng) == 0) tri[0] = mesh.triangles[0][1];
      }
      return mesh;
    };
    TriangleMesh tissue = soup(40);
    TriangleMesh tool = soup(25);
    SphereTree tissue_tree;
    SphereTree tool_tree;
    tissue_tree.build(tissue);
    tool_tree.build(tool);
    RigidPose pose;
    const int quarter = trial % 4;  // rotation by quarter * 90 degrees about z: exact entries
    const double c = quarter == 0 ? 1 : quarter == 2 ? -1 : 0;
    const double s = quarter == 1 ? 1 : quarter == 3 ? -1 : 0;
    pose.rotation[0] = Vec3(c, s, 0.0);  // columns
    pose.rotation[1] = Vec3(-s, c, 0.0);
    pose.translation = Vec3(grid(rng) - 3, grid(rng) - 3, trial % 3 == 0 ? 0 : grid(rng) - 3);
    const auto expected = collide_brute_force(tissue, tool, pose);
    for (Collider* collider : {&field, &dual}) {
      ASSERT_TRUE(collider->collide(tissue_tree, tissue, tool_tree, tool, pose));
      ASSERT_EQ(pairs_of(*collider), expected) << "trial " << trial << (collider == &field ? " (field)" : " (dual descent)");
      expect_leaf_lists(*collider, tissue_tree, tool_tree);
    }
    total += static_cast<std::int64_t>(expected.size());
  }
  EXPECT_GT(total, 1000);
}

// A smooth displacement of up to 2 mm, then a refit: the pairs still equal brute force on the
// moved surface (a refit that let a child poke out of its parent would lose pairs here).
TEST(Collide, EqualsBruteForceAfterDeformationAndRefit) {
  ProstateScene scene(2816);
  TriangleMesh& surface = scene.prostate.surface;
  const std::vector<Vec3> rest = surface.positions;
  Collider field = collider_using(CollisionMethod::kToolField);
  Collider dual = collider_using(CollisionMethod::kDualDescent);
  std::mt19937_64 rng(5);
  for (int step = 1; step <= 8; ++step) {
    const double amplitude = 0.00025 * step;  // up to 2 mm
    for (std::size_t v = 0; v < rest.size(); ++v) {
      const Vec3& p = rest[v];
      surface.positions[v] = p + amplitude * Vec3(std::sin(180 * p.z + step), std::cos(150 * p.x - step),
                                                  std::sin(120 * p.y + 0.5 * step));
    }
    scene.tissue_tree.refit(surface);
    testing::expect_tree_invariants(scene.tissue_tree);
    for (int i = 0; i < 40; ++i) {
      const RigidPose pose = random_channel_pose(rng);
      const auto expected = collide_brute_force(surface, scene.tool, pose);
      for (Collider* collider : {&field, &dual}) {
        ASSERT_TRUE(collider->collide(scene.tissue_tree, surface, scene.tool_tree, scene.tool, pose));
        ASSERT_EQ(pairs_of(*collider), expected) << "step " << step << " pose " << i;
      }
    }
  }
}

TEST(Collide, OverflowIsReportedNotAllocated) {
  ProstateScene scene(1296);
  Collider collider;
  collider.reserve(2, 8);
  std::mt19937_64 rng(9);
  RigidPose pose;
  std::vector<TrianglePair> expected;
  while (expected.size() < 10) {
    pose = random_channel_pose(rng);
    expected = collide_brute_force(scene.prostate.surface, scene.tool, pose);
  }
  EXPECT_FALSE(collider.collide(scene.tissue_tree, scene.prostate.surface, scene.tool_tree, scene.tool, pose));
  EXPECT_TRUE(collider.overflowed());
  collider.reserve(1 << 14, 1 << 16);
  EXPECT_TRUE(collider.collide(scene.tissue_tree, scene.prostate.surface, scene.tool_tree, scene.tool, pose));
  EXPECT_EQ(pairs_of(collider), expected);
}

}  // namespace
}  // namespace resecto
