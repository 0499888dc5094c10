// The refit kernels agree bit for bit: the AVX2 paths must give exactly the one-at-a-time spheres
// (the same tree on machines with and without AVX2), and a spheres-only tree's refit must give the
// spheres a plain children-first pass over the same functions gives, and keep covering its leaves
// through insertions and removals.
#include "rtcore/collision/sphere_refit_kernel.h"

#include <gtest/gtest.h>

#include <cstring>
#include <random>
#include <span>
#include <vector>

#include "scene.h"

namespace resecto {
namespace {

bool same_bits(const Sphere& a, const Sphere& b) { return std::memcmp(&a, &b, sizeof(Sphere)) == 0; }

/// The children of `nodes`, in their order, as the tree hands them to the merges.
std::vector<ChildPair> children_of(const std::vector<ChildPair>& by_node, std::span<const std::int32_t> nodes) {
  std::vector<ChildPair> children;
  for (const std::int32_t n : nodes) children.push_back(by_node[static_cast<std::size_t>(n)]);
  return children;
}

TriangleMesh jittered_gland(std::uint64_t seed) {
  TriangleMesh mesh = generate_prostate(1296).surface;
  std::mt19937_64 random(seed);
  std::uniform_real_distribution<double> jitter(-1e-3, 1e-3);
  for (Vec3& p : mesh.positions) p += Vec3(jitter(random), jitter(random), jitter(random));
  return mesh;
}

TEST(SphereRefitKernel, Avx2CentroidSpheresMatchThePortableOnesBitForBit) {
  if (!cpu_has_avx2()) GTEST_SKIP() << "no AVX2 on this processor: only the portable path runs";
  const TriangleMesh mesh = jittered_gland(3);
  std::vector<LeafPiece> pieces(mesh.triangle_count());
  std::vector<std::int32_t> leaves;
  for (std::uint32_t t = 0; t < mesh.triangle_count(); ++t) {
    pieces[t].triangle = mesh.triangle_count() - 1 - t;  // leaves need not follow the triangles' order
    leaves.push_back(static_cast<std::int32_t>(t));
  }
  // Every remainder of four, and a span that starts inside the array.
  for (const std::size_t count : {std::size_t{0}, std::size_t{1}, std::size_t{3}, std::size_t{7}, leaves.size()}) {
    const std::span<const std::int32_t> span(leaves.data() + (count < 8 ? 5 : 0), count);
    std::vector<Triangle> corners;  // in the span's order, as the tree keeps them
    for (const std::int32_t leaf : span) corners.push_back(mesh.triangles[pieces[static_cast<std::size_t>(leaf)].triangle]);
    std::vector<Sphere> portable(leaves.size()), simd(leaves.size());
    centroid_spheres_portable(mesh.positions.data(), corners.data(), span, portable.data());
    centroid_spheres_avx2(mesh.positions.data(), corners.data(), span, simd.data());
    for (std::size_t n = 0; n < leaves.size(); ++n) ASSERT_TRUE(same_bits(portable[n], simd[n])) << "leaf " << n << " of a span of " << count;
  }
}

TEST(SphereRefitKernel, Avx2SlicedPieceSpheresMatchThePortableOnesBitForBit) {
  if (!cpu_has_avx2()) GTEST_SKIP() << "no AVX2 on this processor: only the portable path runs";
  const TriangleMesh mesh = jittered_gland(7);
  // Every triangle cut into 2 to 5 slices about each of its corners: every slice a leaf.
  std::vector<LeafPiece> pieces;
  for (std::uint32_t t = 0; t < mesh.triangle_count(); ++t) {
    const auto slices = static_cast<std::uint16_t>(2 + t % 4);
    for (std::uint16_t slice = 0; slice < slices; ++slice) {
      pieces.push_back({t, slice, slices, static_cast<std::uint8_t>((t / 4 + slice) % 3)});
    }
  }
  std::vector<std::int32_t> leaves(pieces.size());
  for (std::size_t n = 0; n < leaves.size(); ++n) leaves[n] = static_cast<std::int32_t>(n);
  for (const std::size_t count : {std::size_t{3}, std::size_t{6}, leaves.size()}) {
    const std::span<const std::int32_t> span(leaves.data() + (count < 8 ? 9 : 0), count);
    std::vector<SliceOperands> operands;  // in the span's order, as the tree keeps them
    for (const std::int32_t leaf : span) operands.push_back(SphereTree::slice_operands(mesh, pieces[static_cast<std::size_t>(leaf)]));
    std::vector<Sphere> portable(leaves.size()), simd(leaves.size());
    sliced_piece_spheres_portable(mesh.positions.data(), operands.data(), span, portable.data());
    sliced_piece_spheres_avx2(mesh.positions.data(), operands.data(), span, simd.data());
    for (std::size_t n = 0; n < leaves.size(); ++n) ASSERT_TRUE(same_bits(portable[n], simd[n])) << "piece " << n << " of a span of " << count;
    for (const std::int32_t leaf : span) {
      const auto n = static_cast<std::size_t>(leaf);
      ASSERT_TRUE(same_bits(portable[n], SphereTree::piece_sphere(mesh, pieces[n]))) << "piece " << n << ": not piece_sphere's bits";
    }
  }
}

TEST(SphereRefitKernel, Avx2MergesMatchThePortableOnesInEveryCase) {
  if (!cpu_has_avx2()) GTEST_SKIP() << "no AVX2 on this processor: only the portable path runs";
  // Pairs of random spheres: disjoint, overlapping, one inside the other either way, and equal.
  std::mt19937_64 random(11);
  std::uniform_real_distribution<double> coordinate(-0.05, 0.05), radius(1e-4, 0.02);
  const std::int32_t pairs = 403;
  std::vector<Sphere> spheres(static_cast<std::size_t>(3 * pairs));
  std::vector<ChildPair> links(spheres.size());  // by node
  std::vector<std::int32_t> parents;
  for (std::int32_t k = 0; k < pairs; ++k) {
    const std::int32_t parent = 3 * k, left = parent + 1, right = parent + 2;
    Sphere& a = spheres[static_cast<std::size_t>(left)];
    Sphere& b = spheres[static_cast<std::size_t>(right)];
    a = {Vec3(coordinate(random), coordinate(random), coordinate(random)), radius(random)};
    b = {Vec3(coordinate(random), coordinate(random), coordinate(random)), radius(random)};
    if (k % 5 == 1) b = {a.center + Vec3(0.1 * a.radius, 0.0, 0.0), 0.5 * a.radius};  // a holds b
    if (k % 5 == 2) a = {b.center - Vec3(0.0, 0.1 * b.radius, 0.0), 0.5 * b.radius};  // b holds a
    if (k % 5 == 3) b = a;                                                             // the same sphere
    links[static_cast<std::size_t>(parent)] = {left, right};
    parents.push_back(parent);
  }
  // Spans of every remainder of four: the last one to three merges run as padded lanes.
  for (const std::size_t count : {std::size_t{1}, std::size_t{2}, std::size_t{6}}) {
    const std::span<const std::int32_t> span(parents.data() + 7, count);
    const std::vector<ChildPair> children = children_of(links, span);
    std::vector<Sphere> portable = spheres, simd = spheres;
    merge_children_portable(children.data(), span, portable.data());
    merge_children_avx2(children.data(), span, simd.data());
    for (std::size_t n = 0; n < spheres.size(); ++n) ASSERT_TRUE(same_bits(portable[n], simd[n])) << "sphere " << n << " of a span of " << count;
  }
  const std::vector<ChildPair> children = children_of(links, parents);
  std::vector<Sphere> portable = spheres, simd = spheres;
  merge_children_portable(children.data(), parents, portable.data());
  merge_children_avx2(children.data(), parents, simd.data());
  for (const std::int32_t parent : parents) {
    const auto p = static_cast<std::size_t>(parent);
    ASSERT_TRUE(same_bits(portable[p], simd[p])) << "pair " << parent / 3;
    for (const std::int32_t child : {links[p].left, links[p].right}) {
      const Sphere& c = portable[static_cast<std::size_t>(child)];
      EXPECT_LE(length(c.center - portable[p].center) + c.radius, portable[p].radius) << "pair " << parent / 3 << " does not hold its child";
    }
  }
}

// What SphereTree::refit must give a spheres-only tree: each leaf from its piece, then each internal
// node from its children, one at a time, children first.
std::vector<Sphere> reference_refit(const SphereTree& tree, const TriangleMesh& mesh) {
  std::vector<Sphere> spheres = tree.spheres();
  const auto& links = tree.links();
  std::vector<std::int32_t> order;
  std::vector<std::int32_t> stack{tree.root()};
  while (!stack.empty()) {
    const std::int32_t n = stack.back();
    stack.pop_back();
    order.push_back(n);
    if (!tree.is_leaf(n)) {
      stack.push_back(links[static_cast<std::size_t>(n)].left);
      stack.push_back(links[static_cast<std::size_t>(n)].right);
    }
  }
  for (auto n = order.rbegin(); n != order.rend(); ++n) {
    const auto node = static_cast<std::size_t>(*n);
    if (tree.is_leaf(*n)) {
      const LeafPiece& piece = tree.pieces()[node];
      const Triangle& t = mesh.triangles[piece.triangle];
      spheres[node] = piece.slices == 1 ? centroid_sphere(mesh.positions[t[0]], mesh.positions[t[1]], mesh.positions[t[2]])
                                        : SphereTree::piece_sphere(mesh, piece);
    } else {
      spheres[node] = enclosing_sphere(spheres[static_cast<std::size_t>(links[node].left)], spheres[static_cast<std::size_t>(links[node].right)]);
    }
  }
  return spheres;
}

/// Removes and inserts random triangles, moves every vertex and refits, `rounds` times: each refit
/// gives the spheres that a children-first pass of the one-at-a-time functions gives.
void expect_refit_through_edits(TriangleMesh mesh, int rounds) {
  const std::vector<Vec3> rest = mesh.positions;
  SphereTree tree;
  tree.set_slabs(false);
  tree.build(mesh);
  std::mt19937_64 random(17);
  std::uniform_real_distribution<double> jitter(-1e-3, 1e-3);
  std::uniform_int_distribution<std::uint32_t> pick(0, static_cast<std::uint32_t>(mesh.triangle_count() - 1));
  std::vector<bool> in_tree(mesh.triangle_count(), true);
  int sliced = 0;
  for (const LeafPiece& piece : tree.pieces()) sliced += piece.slices > 1;
  EXPECT_GT(sliced, 0) << "the gland's long thin triangles make sliced leaves, which the refit takes one at a time";
  for (int round = 0; round < rounds; ++round) {
    for (int edit = 0; edit < 25; ++edit) {
      const std::uint32_t t = pick(random);
      if (in_tree[t]) {
        tree.remove_triangle(t);
      } else {
        tree.insert_triangle(mesh, t);
      }
      in_tree[t] = !in_tree[t];
    }
    for (std::size_t v = 0; v < rest.size(); ++v) mesh.positions[v] = rest[v] + Vec3(jitter(random), jitter(random), jitter(random));
    const std::vector<Sphere> expected = reference_refit(tree, mesh);
    tree.refit(mesh);
    const auto& links = tree.links();
    for (std::size_t n = 0; n < expected.size(); ++n) {
      if (links[n].height < 0) continue;  // a free slot
      ASSERT_TRUE(same_bits(tree.spheres()[n], expected[n])) << "node " << n << " after round " << round;
    }
    testing::expect_tree_invariants(tree);
    if (::testing::Test::HasFatalFailure()) return;
  }
}

/// The live nodes of a spheres-only tree over `mesh`: which refit order the tree gets.
std::int32_t spheres_only_nodes(const TriangleMesh& mesh) {
  SphereTree probe;
  probe.set_slabs(false);
  probe.build(mesh);
  return probe.live_node_count();
}

TEST(SphereRefitKernel, SpheresOnlyRefitGivesTheChildrenFirstSpheresThroughInsertionsAndRemovals) {
  const TriangleMesh mesh = jittered_gland(5);
  ASSERT_LE(spheres_only_nodes(mesh), SphereTree::kRefitWholeTreeNodes) << "a tree refitted whole, a height at a time";
  expect_refit_through_edits(mesh, 40);
}

TEST(SphereRefitKernel, ABlockedRefitGivesTheChildrenFirstSpheresThroughInsertionsAndRemovals) {
  TriangleMesh mesh = generate_prostate(20000).surface;
  ASSERT_GT(spheres_only_nodes(mesh), SphereTree::kRefitWholeTreeNodes) << "a tree refitted in cache-sized subtrees first";
  expect_refit_through_edits(std::move(mesh), 6);
}

}  // namespace
}  // namespace resecto
