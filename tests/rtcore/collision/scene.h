// Checks every collision test makes on its trees: the tree invariants and the slabs' cover (the
// scenes and the tool's poses are rtcore/scenes/collision_poses.h, shared with the benchmark).
#pragma once

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "rtcore/anatomy/prostate.h"
#include "rtcore/anatomy/resectoscope.h"
#include "rtcore/collision/collide.h"
#include "rtcore/scenes/collision_poses.h"

namespace resecto::testing {

/// Checks the structure of a tree: parent and child links agree, heights are right, every node's
/// sphere covers every leaf sphere below it, every live node is reachable and every other slot free.
inline void expect_tree_invariants(const SphereTree& tree) {
  const auto& links = tree.links();
  const auto& spheres = tree.spheres();
  std::int32_t reachable = 0;
  std::int32_t leaves = 0;
  if (!tree.empty()) {
    ASSERT_EQ(links[tree.root()].parent, SphereTree::kNoNode);
    std::vector<std::int32_t> stack{tree.root()};
    while (!stack.empty()) {
      const std::int32_t n = stack.back();
      stack.pop_back();
      ++reachable;
      ASSERT_GE(links[n].height, 0) << "free node " << n << " is reachable";
      if (tree.is_leaf(n)) {
        ++leaves;
        ASSERT_EQ(links[n].height, 0);
        // Covered by every ancestor.
        for (std::int32_t a = links[n].parent; a != SphereTree::kNoNode; a = links[a].parent) {
          const double reach = length(spheres[n].center - spheres[a].center) + spheres[n].radius;
          ASSERT_LE(reach, spheres[a].radius * (1.0 + 1e-9)) << "leaf " << n << " pokes out of ancestor " << a;
        }
        continue;
      }
      const std::int32_t l = links[n].left;
      const std::int32_t r = links[n].right;
      ASSERT_EQ(links[l].parent, n);
      ASSERT_EQ(links[r].parent, n);
      ASSERT_EQ(links[n].height, 1 + std::max(links[l].height, links[r].height)) << "node " << n;
      stack.push_back(l);
      stack.push_back(r);
    }
  }
  EXPECT_EQ(leaves, tree.leaf_count());
  EXPECT_EQ(reachable, tree.live_node_count());
  EXPECT_EQ(reachable + tree.free_node_count(), tree.node_capacity()) << "nodes lost or leaked";
}

/// The corners of the part of its triangle a leaf covers (the triangle, or a slab across it).
inline std::vector<Vec3> piece_corners(const TriangleMesh& mesh, const LeafPiece& piece) {
  const Triangle& tri = mesh.triangles[piece.triangle];
  if (piece.slices == 1) return {mesh.positions[tri[0]], mesh.positions[tri[1]], mesh.positions[tri[2]]};
  const Vec3& b = mesh.positions[tri[piece.apex]];
  const Vec3& x = mesh.positions[tri[(piece.apex + 1) % 3]];
  const Vec3& y = mesh.positions[tri[(piece.apex + 2) % 3]];
  const double t0 = static_cast<double>(piece.slice) / piece.slices;
  const double t1 = static_cast<double>(piece.slice + 1) / piece.slices;
  return {x * (1.0 - t0) + b * t0, y * (1.0 - t0) + b * t0, x * (1.0 - t1) + b * t1, y * (1.0 - t1) + b * t1};
}

/// Checks the slab bounds against the mesh: every corner of what every live leaf covers lies inside
/// the leaf's slab and inside every ancestor's, to rounding.
inline void expect_slabs_cover(const SphereTree& tree, const TriangleMesh& mesh) {
  const auto& links = tree.links();
  for (std::int32_t leaf = 0; leaf < tree.node_capacity(); ++leaf) {
    if (links[leaf].height != 0) continue;  // internal or free
    const std::vector<Vec3> corners = piece_corners(mesh, tree.pieces()[leaf]);
    for (std::int32_t n = leaf; n != SphereTree::kNoNode; n = links[n].parent) {
      const Slab& slab = tree.slabs()[n];
      ASSERT_NEAR(length(slab.normal), 1.0, 1e-12) << "node " << n;
      for (const Vec3& p : corners) {
        const double along = dot(slab.normal, p);
        const double eps = 1e-9 * (std::abs(along) + 1e-3);
        ASSERT_GE(along, slab.lo - eps) << "corner of leaf " << leaf << " below the slab of node " << n;
        ASSERT_LE(along, slab.hi + eps) << "corner of leaf " << leaf << " above the slab of node " << n;
      }
    }
  }
}

/// A closed outward tetrahedron with legs of `side` from the origin: past 1e154 its squared lengths
/// overflow to infinity, at 1e150 its volume does.
inline TriangleMesh corner_tetrahedron(double side) {
  TriangleMesh mesh;
  mesh.positions = {{0, 0, 0}, {side, 0, 0}, {0, side, 0}, {0, 0, side}};
  mesh.triangles = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
  return mesh;
}

}  // namespace resecto::testing
