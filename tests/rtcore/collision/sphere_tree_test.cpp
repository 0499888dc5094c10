// Sphere-tree structure: leaves cover every point of every triangle (long thin ones with several
// leaves), nodes cover their leaves, and long random runs of refit, insert and remove keep every
// invariant, lose or leak no node and stay shallow until the rebuild policy acts.
#include "rtcore/collision/sphere_tree.h"

#include <gtest/gtest.h>

#include <limits>
#include <random>

#include "scene.h"

namespace resecto {
namespace {

// Random points of each triangle (its corners included) lie in one of its leaves' spheres.
void expect_triangles_covered(const SphereTree& tree, const TriangleMesh& mesh, std::uint32_t t, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const Triangle& tri = mesh.triangles[t];
  for (int k = 0; k < 40; ++k) {
    double u = unit(rng), v = unit(rng);
    if (k < 3) u = k == 1, v = k == 2;
    if (u + v > 1.0) u = 1.0 - u, v = 1.0 - v;
    const Vec3 p = mesh.positions[tri[0]] * (1.0 - u - v) + mesh.positions[tri[1]] * u + mesh.positions[tri[2]] * v;
    bool covered = false;
    for (std::int32_t n = tree.first_leaf_of_triangle(t); n != SphereTree::kNoNode; n = tree.next_leaf_of_triangle(n)) {
      const Sphere& s = tree.spheres()[n];
      covered = covered || length(p - s.center) <= s.radius;
    }
    ASSERT_TRUE(covered) << "triangle " << t << " point " << k;
  }
}

TEST(SphereTree, LeavesCoverEveryTriangleAndThinStripsGetSeveral) {
  const ResectoscopeModel tool = generate_resectoscope();
  SphereTree tree;
  tree.build(tool.sheath);
  std::mt19937_64 rng(1);
  int most_leaves = 0;
  for (std::uint32_t t = 0; t < tool.sheath.triangle_count(); ++t) {
    expect_triangles_covered(tree, tool.sheath, t, rng);
    int leaves = 0;
    for (std::int32_t n = tree.first_leaf_of_triangle(t); n != SphereTree::kNoNode; n = tree.next_leaf_of_triangle(n)) {
      ASSERT_EQ(tree.pieces()[n].triangle, t);
      ++leaves;
    }
    most_leaves = std::max(most_leaves, leaves);
  }
  // A 120 mm side strip: a row of slabs (SphereTree::kSliceAspect times as long as wide), each far
  // smaller than the strip; compact triangles (the caps, the loop) keep one leaf.
  EXPECT_GE(most_leaves, 10);
  double largest_leaf = 0.0;
  for (std::int32_t n = 0; n < tree.node_capacity(); ++n) {
    if (tree.is_leaf(n)) largest_leaf = std::max(largest_leaf, tree.spheres()[n].radius);
  }
  EXPECT_LT(largest_leaf, 0.006);
  testing::expect_tree_invariants(tree);
}

TEST(SphereTree, BuildIsBalancedAndDeterministic) {
  const ProstateModel gland = generate_prostate(8640);
  SphereTree a;
  SphereTree b;
  a.build(gland.surface);
  b.build(gland.surface);
  testing::expect_tree_invariants(a);
  const SphereTreeQuality q = a.quality();
  EXPECT_EQ(q.leaves, a.leaf_count());
  EXPECT_LE(q.height, 1.5 * std::log2(q.leaves) + 2) << "leaves " << q.leaves;
  EXPECT_FALSE(a.should_rebuild());
  // Compact triangles keep one leaf each; the layout is depth-first (a left child follows its parent).
  EXPECT_LT(a.leaf_count(), static_cast<std::int32_t>(gland.surface.triangle_count() * 5 / 4));
  EXPECT_EQ(a.root(), 0);
  for (std::int32_t n = 0; n < a.node_capacity(); ++n) {
    if (!a.is_leaf(n)) {
      ASSERT_EQ(a.links()[n].left, n + 1) << "node " << n;
    }
  }
  ASSERT_EQ(a.node_capacity(), b.node_capacity());
  for (std::int32_t n = 0; n < a.node_capacity(); ++n) {
    ASSERT_EQ(a.spheres()[n].center, b.spheres()[n].center);
    ASSERT_EQ(a.spheres()[n].radius, b.spheres()[n].radius);
    ASSERT_EQ(a.links()[n].left, b.links()[n].left);
  }
  std::mt19937_64 rng(2);
  for (std::uint32_t t = 0; t < gland.surface.triangle_count(); t += 7) expect_triangles_covered(a, gland.surface, t, rng);
}

// A build in stages of a few hundred leaf visits (the core's collision job takes a decayed tree's
// rebuild a few levels a step) ends in the very tree a whole rebuild makes, and can be dropped midway.
TEST(SphereTree, AStagedBuildEndsInTheWholeRebuildsTree) {
  ProstateModel gland = generate_prostate(1296);
  for (const bool slabs : {false, true}) {
    SphereTree whole;
    whole.set_slabs(slabs);
    whole.build(gland.surface);
    for (std::uint32_t t = 0; t < gland.surface.triangle_count(); t += 5) whole.remove_triangle(t);
    SphereTree staged;
    staged.set_slabs(slabs);
    staged.begin_build(gland.surface, whole);
    EXPECT_TRUE(staged.build_pending());
    int calls = 1;
    while (!staged.continue_build(300)) ++calls;
    EXPECT_FALSE(staged.build_pending());
    EXPECT_GT(calls, 20) << "it stopped and went on";
    whole.rebuild(gland.surface);
    testing::expect_tree_invariants(staged);
    ASSERT_EQ(staged.node_capacity(), whole.node_capacity());
    ASSERT_EQ(staged.leaf_count(), whole.leaf_count());
    for (std::int32_t n = 0; n < whole.node_capacity(); ++n) {
      ASSERT_EQ(staged.spheres()[n].center, whole.spheres()[n].center) << "node " << n;
      ASSERT_EQ(staged.spheres()[n].radius, whole.spheres()[n].radius) << "node " << n;
      ASSERT_EQ(staged.links()[n].parent, whole.links()[n].parent) << "node " << n;
      ASSERT_EQ(staged.links()[n].left, whole.links()[n].left) << "node " << n;
      ASSERT_EQ(staged.links()[n].right, whole.links()[n].right) << "node " << n;
      ASSERT_EQ(staged.links()[n].height, whole.links()[n].height) << "node " << n;
      ASSERT_EQ(staged.pieces()[n].triangle, whole.pieces()[n].triangle) << "node " << n;
      if (slabs) {
        ASSERT_EQ(staged.slabs()[n].normal, whole.slabs()[n].normal) << "node " << n;
      }
    }
    for (std::uint32_t t = 0; t < gland.surface.triangle_count(); ++t) {
      ASSERT_EQ(staged.first_leaf_of_triangle(t), whole.first_leaf_of_triangle(t)) << "triangle " << t;
    }
    // Dropped midway, the tree is empty and a new build starts clean.
    staged.begin_build(gland.surface, whole);
    EXPECT_FALSE(staged.continue_build(300));
    staged.abandon_build();
    EXPECT_FALSE(staged.build_pending());
    EXPECT_TRUE(staged.empty());
    EXPECT_EQ(staged.first_leaf_of_triangle(1), SphereTree::kNoNode);
    staged.begin_build(gland.surface, whole);
    EXPECT_TRUE(staged.continue_build(std::numeric_limits<std::int64_t>::max()));
    testing::expect_tree_invariants(staged);
    EXPECT_EQ(staged.leaf_count(), whole.leaf_count());
  }
}

TEST(SphereTree, CoincidentTrianglesFallBackToMedianSplits) {
  TriangleMesh mesh;
  mesh.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  for (int i = 0; i < 33; ++i) mesh.triangles.push_back({0, 1, 2});
  SphereTree tree;
  tree.build(mesh);
  testing::expect_tree_invariants(tree);
  EXPECT_EQ(tree.quality().height, 6);  // ceil(log2(33))
}

// 10,000 random operations: refits after vertex jitter, removals and re-insertions of triangles.
TEST(SphereTree, InvariantsHoldOverTenThousandRandomOperations) {
  ProstateModel gland = generate_prostate(1296);
  TriangleMesh& mesh = gland.surface;
  const std::vector<Vec3> rest = mesh.positions;
  SphereTree tree;
  tree.build(mesh);
  std::vector<bool> in_tree(mesh.triangle_count(), true);
  std::mt19937_64 rng(42);
  std::uniform_int_distribution<std::uint32_t> pick(0, static_cast<std::uint32_t>(mesh.triangle_count() - 1));
  std::uniform_real_distribution<double> jitter(-0.001, 0.001);
  const std::int32_t start_capacity = tree.node_capacity();
  int rebuilds = 0;
  int removals = 0;
  int insertions = 0;
  for (int op = 0; op < 10000; ++op) {
    const int kind = static_cast<int>(rng() % 10);
    if (kind == 0) {
      for (std::size_t v = 0; v < rest.size(); ++v) mesh.positions[v] = rest[v] + Vec3(jitter(rng), jitter(rng), jitter(rng));
      tree.refit(mesh);
    } else {
      // A triangle at random: removed when present, inserted back (from its moved vertices) when not.
      const std::uint32_t t = pick(rng);
      if (in_tree[t]) {
        tree.remove_triangle(t);
        ++removals;
      } else {
        tree.insert_triangle(mesh, t);
        ++insertions;
      }
      in_tree[t] = !in_tree[t];
    }
    const SphereTreeQuality q = tree.quality();
    ASSERT_LE(q.height, q.height_bound + 1) << "op " << op;  // one insert past the bound at most
    if (tree.should_rebuild()) {
      tree.rebuild(mesh);
      ++rebuilds;
    }
    if (op % 250 == 0 || op == 9999) {
      testing::expect_tree_invariants(tree);
      testing::expect_slabs_cover(tree, mesh);
      if (HasFatalFailure() || HasNonfatalFailure()) FAIL() << "op " << op;
      std::int32_t leaves = 0;
      for (std::uint32_t t = 0; t < mesh.triangle_count(); ++t) {
        const bool has_leaf = tree.first_leaf_of_triangle(t) != SphereTree::kNoNode;
        ASSERT_EQ(has_leaf, in_tree[t]) << "triangle " << t << " op " << op;
        for (std::int32_t n = tree.first_leaf_of_triangle(t); n != SphereTree::kNoNode; n = tree.next_leaf_of_triangle(n)) ++leaves;
      }
      ASSERT_EQ(leaves, tree.leaf_count());
    }
  }
  EXPECT_GT(removals, 3000);
  EXPECT_GT(insertions, 3000);
  // Freed slots are reused: about half the triangles are in the tree, so no growth past the start.
  EXPECT_LE(tree.node_capacity(), start_capacity + 64);
  std::cout << "rebuilds: " << rebuilds << ", final height " << tree.quality().height << " for " << tree.leaf_count()
            << " leaves\n";
}

TEST(SphereTree, RemovingEveryTriangleFreesEveryNodeAndInsertingReusesThem) {
  const ProstateModel gland = generate_prostate(1296);
  SphereTree tree;
  tree.build(gland.surface);
  const std::int32_t capacity = tree.node_capacity();
  for (std::uint32_t t = 0; t < gland.surface.triangle_count(); ++t) tree.remove_triangle(t);
  EXPECT_TRUE(tree.empty());
  EXPECT_EQ(tree.live_node_count(), 0);
  EXPECT_EQ(tree.free_node_count(), capacity);
  for (std::uint32_t t = 0; t < gland.surface.triangle_count(); ++t) tree.insert_triangle(gland.surface, t);
  EXPECT_EQ(tree.node_capacity(), capacity);
  testing::expect_tree_invariants(tree);
}


TEST(SphereTree, HugeCoordinatesKeepOneLeafPerTriangle) {
  // Their slice count was NaN, cast to an int: billions of leaves (5-7.5 GB) before the readers
  // refused such files. A programmatic caller still gets a bounded tree.
  for (const double side : {1e150, 1e155, 1e300}) {
    SphereTree tree;
    tree.build(testing::corner_tetrahedron(side));
    EXPECT_LE(tree.leaf_count(), 4 * SphereTree::kMaxSlices) << side;
  }
}

}  // namespace
}  // namespace resecto
