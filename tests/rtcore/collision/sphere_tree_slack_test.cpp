// The refit with slack (SphereTree::set_refit_slack): a refit fits again only the leaves whose
// corners moved beyond the slack, yet every triangle stays inside its leaves, every node holds its
// children, and a search by the tree finds exactly the triangles a brute-force pass finds, through
// local presses, jitter below the slack, edits and rebuilds; on the gland and on the resectoscope,
// whose long strips are cut into several leaves.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <vector>

#include "rtcore/geometry/closest_point.h"
#include "scene.h"

namespace resecto {
namespace {

double diagonal(const TriangleMesh& mesh) {
  Vec3 lo = mesh.positions[0], hi = mesh.positions[0];
  for (const Vec3& p : mesh.positions) lo = glm::min(lo, p), hi = glm::max(hi, p);
  return length(hi - lo);
}

// Every corner of what each live leaf covers lies in its sphere (a sphere holds a triangle or slab
// when it holds its corners).
void expect_leaves_cover(const SphereTree& tree, const TriangleMesh& mesh) {
  for (std::int32_t leaf = 0; leaf < tree.node_capacity(); ++leaf) {
    if (tree.links()[leaf].height != 0) continue;
    const Sphere& s = tree.spheres()[leaf];
    for (const Vec3& p : testing::piece_corners(mesh, tree.pieces()[leaf])) {
      ASSERT_LE(length(p - s.center), s.radius * (1.0 + 1e-9)) << "leaf " << leaf << " of triangle " << tree.pieces()[leaf].triangle;
    }
  }
}

// The triangles within `reach` of `p`: by the tree (a node is opened when its sphere comes within
// reach) and by every triangle of the tree.
std::vector<std::uint32_t> near_by_tree(const SphereTree& tree, const TriangleMesh& mesh, const Vec3& p, double reach) {
  std::vector<std::uint32_t> found;
  if (tree.empty()) return found;
  std::vector<std::int32_t> stack{tree.root()};
  while (!stack.empty()) {
    const std::int32_t n = stack.back();
    stack.pop_back();
    const Sphere& s = tree.spheres()[n];
    if (length(p - s.center) > s.radius + reach) continue;
    if (!tree.is_leaf(n)) {
      stack.push_back(tree.links()[n].left);
      stack.push_back(tree.links()[n].right);
      continue;
    }
    const std::uint32_t t = tree.pieces()[n].triangle;
    const Triangle& tri = mesh.triangles[t];
    if (length(p - closest_point_on_triangle(p, mesh.positions[tri[0]], mesh.positions[tri[1]], mesh.positions[tri[2]])) <= reach) found.push_back(t);
  }
  std::sort(found.begin(), found.end());
  found.erase(std::unique(found.begin(), found.end()), found.end());
  return found;
}

std::vector<std::uint32_t> near_by_brute_force(const std::vector<bool>& in_tree, const TriangleMesh& mesh, const Vec3& p, double reach) {
  std::vector<std::uint32_t> found;
  for (std::uint32_t t = 0; t < mesh.triangle_count(); ++t) {
    const Triangle& tri = mesh.triangles[t];
    if (in_tree[t] && length(p - closest_point_on_triangle(p, mesh.positions[tri[0]], mesh.positions[tri[1]], mesh.positions[tri[2]])) <= reach) {
      found.push_back(t);
    }
  }
  return found;
}

// A run of deformations: local presses (the vertices near a random point pushed up to three slacks
// along a random direction, falling off with distance), jitter of every vertex below half the slack,
// and now and then a triangle removed or put back and the rebuild policy's rebuilds.
void run_presses(TriangleMesh& mesh, std::uint64_t seed) {
  const double size = diagonal(mesh);
  const double slack = 0.004 * size;
  SphereTree tree;
  tree.set_slabs(false);
  tree.set_refit_slack(slack);
  tree.build(mesh);
  for (int first = 0; first < 2; ++first) {
    tree.refit(mesh);
    EXPECT_EQ(tree.last_refit_leaves(), tree.leaf_count()) << "the refits after the build fit every leaf";
  }
  std::vector<bool> in_tree(mesh.triangle_count(), true);
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  std::uniform_int_distribution<std::size_t> vertex(0, mesh.positions.size() - 1);
  std::uniform_int_distribution<std::uint32_t> triangle(0, static_cast<std::uint32_t>(mesh.triangle_count() - 1));
  int partial = 0, spared = 0;
  for (int step = 0; step < 300; ++step) {
    const int kind = static_cast<int>(rng() % 10);
    if (kind < 6) {
      const Vec3 centre = mesh.positions[vertex(rng)];
      const Vec3 push = Vec3(unit(rng), unit(rng), unit(rng)) * (3.0 * slack);
      const double radius = 0.08 * size;
      for (Vec3& p : mesh.positions) p += push * std::max(0.0, 1.0 - length(p - centre) / radius);
    } else if (kind < 9) {
      for (Vec3& p : mesh.positions) p += Vec3(unit(rng), unit(rng), unit(rng)) * (0.25 * slack);
    } else {
      const std::uint32_t t = triangle(rng);
      if (in_tree[t]) {
        tree.remove_triangle(t);
      } else {
        tree.insert_triangle(mesh, t);
      }
      in_tree[t] = !in_tree[t];
      if (tree.should_rebuild()) tree.rebuild(mesh);
    }
    tree.refit(mesh);
    if (kind < 6 && tree.last_refit_leaves() < tree.leaf_count()) ++partial;
    if (kind >= 6 && kind < 9 && tree.last_refit_leaves() < tree.leaf_count()) ++spared;
    testing::expect_tree_invariants(tree);
    expect_leaves_cover(tree, mesh);
    if (::testing::Test::HasFailure()) FAIL() << "step " << step;
    for (int q = 0; q < 4; ++q) {
      const Vec3 p = mesh.positions[vertex(rng)] + Vec3(unit(rng), unit(rng), unit(rng)) * (0.02 * size);
      const double reach = 0.01 * size * (1.0 + unit(rng));
      ASSERT_EQ(near_by_tree(tree, mesh, p, reach), near_by_brute_force(in_tree, mesh, p, reach)) << "step " << step << " query " << q;
    }
  }
  // The presses are local and the jitter within the slack: most refits fit only some leaves.
  EXPECT_GT(partial, 100);
  EXPECT_GT(spared, 50);
}

TEST(SphereTreeSlack, PressedGlandStaysCoveredAndSearchesEqualBruteForce) {
  ProstateModel gland = generate_prostate(1296);
  run_presses(gland.surface, 7);
}

TEST(SphereTreeSlack, PressedResectoscopeWithSlicedLeavesStaysCovered) {
  const ResectoscopeModel tool = generate_resectoscope();
  TriangleMesh mesh = combined_resectoscope_mesh(tool);
  SphereTree probe;
  probe.build(mesh);
  ASSERT_GT(probe.leaf_count(), static_cast<std::int32_t>(mesh.triangle_count())) << "the sheath's strips are sliced";
  run_presses(mesh, 11);
}

TEST(SphereTreeSlack, JitterWithinTheSlackFitsNoLeafAndAMovedVertexOnlyItsOwn) {
  ProstateModel gland = generate_prostate(1296);
  TriangleMesh& mesh = gland.surface;
  const double slack = 0.004 * diagonal(mesh);
  SphereTree tree;
  tree.set_slabs(false);
  tree.set_refit_slack(slack);
  tree.build(mesh);
  tree.refit(mesh);  // after the build: without slack
  tree.refit(mesh);  // the first without an edit: with it
  for (Vec3& p : mesh.positions) p.x += 0.9 * slack;
  tree.refit(mesh);
  EXPECT_EQ(tree.last_refit_leaves(), 0);
  expect_leaves_cover(tree, mesh);
  // One vertex past the slack: the leaves of its triangles, and nothing else.
  const std::uint32_t moved = mesh.triangles[0][0];
  mesh.positions[moved].y += 2.0 * slack;
  std::int32_t touching = 0;
  for (const Triangle& t : mesh.triangles) touching += std::count(t.begin(), t.end(), moved) > 0 ? 1 : 0;
  tree.refit(mesh);
  EXPECT_EQ(tree.last_refit_leaves(), touching);
  expect_leaves_cover(tree, mesh);
  testing::expect_tree_invariants(tree);
  // An edit: the refit after it fits every leaf without slack, the next with it, and then only what moves.
  tree.remove_triangle(1);
  tree.refit(mesh);
  EXPECT_EQ(tree.last_refit_leaves(), tree.leaf_count());
  tree.refit(mesh);
  EXPECT_EQ(tree.last_refit_leaves(), tree.leaf_count());
  tree.refit(mesh);
  EXPECT_EQ(tree.last_refit_leaves(), 0);
  expect_leaves_cover(tree, mesh);
  // Slack off: every leaf again.
  tree.set_refit_slack(0.0);
  tree.refit(mesh);
  EXPECT_EQ(tree.last_refit_leaves(), tree.leaf_count());
}

}  // namespace
}  // namespace resecto
