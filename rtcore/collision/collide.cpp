// The dual descent over a tissue tree and a rigid tool tree, and the brute-force baseline it is
// checked and raced against.
#include "rtcore/collision/collide.h"

#include <algorithm>
#include <cmath>

#include "rtcore/geometry/triangle_triangle.h"

namespace resecto {
namespace {

double max_abs(const Vec3& v) { return std::max({std::abs(v.x), std::abs(v.y), std::abs(v.z)}); }

// An upper bound on how much the pose's matrix can lengthen a vector: sqrt of the infinity norm of
// R^T R bounds its spectral norm; exactly 1 (up to rounding) for a rotation.
double stretch_bound(const RigidTransform& pose) {
  const auto& r = pose.rotation;
  double worst_row = 0.0;
  for (int i = 0; i < 3; ++i) {
    double row = 0.0;
    for (int j = 0; j < 3; ++j) {
      row += std::abs(r[0][i] * r[0][j] + r[1][i] * r[1][j] + r[2][i] * r[2][j]);
    }
    worst_row = std::max(worst_row, row);
  }
  return std::sqrt(worst_row) * (1.0 + 1e-12);
}

// The descent's one sphere test, on the squared distance between the centres of a tissue sphere
// and a tool sphere in the world (tissue minus tool): every caller rounds alike.
inline bool within_reach(double distance2, double tissue_radius, double tool_radius, double slack) {
  const double reach = tissue_radius + tool_radius + slack;
  return distance2 <= reach * reach;
}
inline bool spheres_meet(const Sphere& tissue, const Sphere& tool, double slack) {
  return within_reach(length_squared(tissue.center - tool.center), tissue.radius, tool.radius, slack);
}

// True when tissue `leaf` is the first leaf of its triangle (chain order) whose sphere meets the tool's.
// The descent reaches every leaf pair whose spheres meet (ancestors cover their leaves with room to
// spare), so the triangle pair is tested exactly once, at that first leaf, with no table.
bool first_meeting_leaf(const SphereTree& tree, const Sphere* spheres, std::uint32_t triangle, std::int32_t leaf,
                        const Sphere& tool_sphere, double slack) {
  for (std::int32_t n = tree.first_leaf_of_triangle(triangle); n != leaf; n = tree.next_leaf_of_triangle(n)) {
    if (spheres_meet(spheres[n], tool_sphere, slack)) return false;
  }
  return true;
}

constexpr bool kTableForSlices = false;

}  // namespace

void Collider::reserve(std::int32_t max_pairs, std::int32_t max_tested_pairs) {
  pairs_.resize(static_cast<std::size_t>(std::max(max_pairs, 1)));
  std::size_t table = 64;
  while (table < 2 * static_cast<std::size_t>(std::max(max_tested_pairs, 1))) table *= 2;
  tested_.assign(table, TestedSlot{});
}

void Collider::next_stamp() {
  if (++stamp_ == 0) {  // wrapped: forget every old mark once
    for (auto* marks : {&l1_stamp_, &l2_stamp_}) std::fill(marks->begin(), marks->end(), 0u);
    std::fill(tested_.begin(), tested_.end(), TestedSlot{});
    stamp_ = 1;
  }
}

void Collider::reserve_tissue_nodes(std::int32_t max_nodes) {
  const auto nodes = static_cast<std::size_t>(std::max(max_nodes, 1));
  l1_stamp_.reserve(nodes);
  l1_.reserve(nodes);
  stack_.reserve(1024);  // the descent needs about the tree's height
}

void Collider::prepare(const SphereTree& tissue_tree, const SphereTree& tool_tree, const TriangleMesh& tool) {
  // resize() allocates only when a tree has grown past every size seen before.
  const auto tissue_nodes = static_cast<std::size_t>(tissue_tree.node_capacity());
  const auto tool_nodes = static_cast<std::size_t>(tool_tree.node_capacity());
  tool_spheres_.resize(tool_nodes);
  tool_vertices_.resize(tool.vertex_count());
  tool_boxes_.resize(tool.triangle_count());
  tool_chain_begin_.resize(tool.triangle_count() + 1);
  tool_chain_.resize(static_cast<std::size_t>(tool_tree.leaf_count()));
  tool_leaf_rank_.resize(tool_nodes);
  std::int32_t at = 0;
  for (std::uint32_t t = 0; t < tool.triangle_count(); ++t) {
    tool_chain_begin_[t] = at;
    std::int32_t rank = 0;
    for (std::int32_t n = tool_tree.first_leaf_of_triangle(t); n != SphereTree::kNoNode; n = tool_tree.next_leaf_of_triangle(n)) {
      tool_chain_[static_cast<std::size_t>(at++)] = n;
      tool_leaf_rank_[static_cast<std::size_t>(n)] = rank++;
    }
  }
  tool_chain_begin_[tool.triangle_count()] = at;
  l1_stamp_.resize(tissue_nodes, 0);
  l1_.resize(tissue_nodes);
  l2_stamp_.resize(tool_nodes, 0);
  l2_.resize(tool_nodes);
  const std::int32_t heights = tissue_tree.links()[tissue_tree.root()].height + tool_tree.links()[tool_tree.root()].height;
  // Depth-first: at most one pending sibling per level, plus the two slots a node's children are
  // written to before it is known which are kept.
  stack_.resize(static_cast<std::size_t>(heights) + 4);
}

bool Collider::first_test_of(std::uint32_t tissue_triangle, std::uint32_t tool_triangle) {
  const std::uint64_t key = (static_cast<std::uint64_t>(tissue_triangle) << 32) | tool_triangle;
  const std::size_t mask = tested_.size() - 1;
  if (2 * (tested_count_ + 1) > tested_.size()) {
    overflowed_ = true;  // table too full to probe: test again rather than risk a lost pair
    return true;
  }
  std::size_t slot = static_cast<std::size_t>((key * 0x9E3779B97F4A7C15ull) >> 20) & mask;
  while (tested_[slot].stamp == stamp_) {
    if (tested_[slot].key == key) return false;
    slot = (slot + 1) & mask;
  }
  tested_[slot] = {key, stamp_};
  ++tested_count_;
  return true;
}

void Collider::test_triangles(const TriangleMesh& tissue, std::uint32_t a, std::uint32_t b, bool may_repeat) {
  // Only a triangle covered by several leaves can reach the same pair twice.
  if (may_repeat && !first_test_of(a, b)) return;
  const Triangle& ta = tissue.triangles[a];
  const Vec3& p0 = tissue.positions[ta[0]];
  const Vec3& p1 = tissue.positions[ta[1]];
  const Vec3& p2 = tissue.positions[ta[2]];
  // Closed boxes that do not meet hold closed triangles that do not meet: exact on coordinates,
  // the same prefilter brute force uses.
  const Aabb& box = tool_boxes_[b];
  if (std::max({p0.x, p1.x, p2.x}) < box.min.x || box.max.x < std::min({p0.x, p1.x, p2.x}) ||
      std::max({p0.y, p1.y, p2.y}) < box.min.y || box.max.y < std::min({p0.y, p1.y, p2.y}) ||
      std::max({p0.z, p1.z, p2.z}) < box.min.z || box.max.z < std::min({p0.z, p1.z, p2.z})) {
    return;
  }
  ++stats_.triangle_tests;
  const Triangle& tb = tool_mesh_->triangles[b];
  if (!triangles_intersect(p0, p1, p2, tool_vertices_[tb[0]], tool_vertices_[tb[1]], tool_vertices_[tb[2]])) return;
  if (pair_count_ == pairs_.size()) {
    overflowed_ = true;
    return;
  }
  pairs_[pair_count_++] = {a, b};
}

bool Collider::collide(const SphereTree& tissue_tree, const TriangleMesh& tissue, const SphereTree& tool_tree,
                       const TriangleMesh& tool, const RigidTransform& tool_pose) {
  pair_count_ = 0;
  l1_count_ = 0;
  l2_count_ = 0;
  tested_count_ = 0;
  overflowed_ = false;
  stats_ = {};
  if (tissue_tree.empty() || tool_tree.empty()) return true;
  prepare(tissue_tree, tool_tree, tool);
  next_stamp();
  pose_ = tool_pose;
  radius_scale_ = stretch_bound(tool_pose);
  tool_mesh_ = &tool;
  // Place the tool once: its tree and mesh are small next to the work of the descent.
  const std::vector<Sphere>& tool_rest = tool_tree.spheres();
  for (std::size_t n = 0; n < tool_rest.size(); ++n) {
    tool_spheres_[n] = {transform_point(pose_, tool_rest[n].center), tool_rest[n].radius * radius_scale_};
  }
  for (std::size_t v = 0; v < tool_vertices_.size(); ++v) tool_vertices_[v] = transform_point(pose_, tool.positions[v]);
  for (std::size_t u = 0; u < tool_boxes_.size(); ++u) {
    const Triangle& t = tool.triangles[u];
    const Vec3& a = tool_vertices_[t[0]];
    const Vec3& b = tool_vertices_[t[1]];
    const Vec3& c = tool_vertices_[t[2]];
    tool_boxes_[u] = {glm::min(a, glm::min(b, c)), glm::max(a, glm::max(b, c))};
  }
  // Rounding of transformed centres and of distances is far below this slack; it only ever lets
  // a few more sphere pairs through to the exact test.
  const Sphere& tool_root = tool_rest[tool_tree.root()];
  const double slack = 1e-12 * (max_abs(tool_pose.translation) + max_abs(tool_root.center) + tool_root.radius +
                                max_abs(tissue_tree.spheres()[tissue_tree.root()].center));

  const Sphere* tissue_spheres = tissue_tree.spheres().data();
  const SphereTreeLinks* tissue_links = tissue_tree.links().data();
  const LeafPiece* tissue_pieces = tissue_tree.pieces().data();
  const Sphere* tool_spheres = tool_spheres_.data();
  const SphereTreeLinks* tool_links = tool_tree.links().data();
  const LeafPiece* tool_pieces = tool_tree.pieces().data();

  // Depth-first with an explicit stack of pairs whose spheres are known to meet: a node opened
  // has both children tested at once, and those that meet are pushed farther first, so the
  // closer is walked first (Figure 11); the distance that orders them is the one that tests them.
  // The walk order depends only on the trees and the pose: deterministic.
  std::int64_t sphere_tests = 1;
  std::int64_t leaf_pairs = 0;
  if (!spheres_meet(tissue_spheres[tissue_tree.root()], tool_spheres[tool_tree.root()], slack)) {
    stats_.sphere_tests = sphere_tests;
    return true;
  }
  NodePair* const stack = stack_.data();
  std::size_t top = 0;
  stack[top++] = {tissue_tree.root(), tool_tree.root()};
  while (top > 0) {
    const NodePair pair = stack[--top];
    const Sphere& s1 = tissue_spheres[pair.tissue];
    const Sphere& s2 = tool_spheres[pair.tool];
    const SphereTreeLinks& links1 = tissue_links[pair.tissue];
    const SphereTreeLinks& links2 = tool_links[pair.tool];
    const bool leaf1 = links1.left == SphereTree::kNoNode;
    const bool leaf2 = links2.left == SphereTree::kNoNode;
    if (leaf1 && leaf2) {
      ++leaf_pairs;
      // Steps 4-9: both leaves. Each goes into its list once (the flags make that O(1)).
      if (l1_stamp_[pair.tissue] != stamp_) {
        l1_stamp_[pair.tissue] = stamp_;
        l1_[l1_count_++] = pair.tissue;
      }
      if (l2_stamp_[pair.tool] != stamp_) {
        l2_stamp_[pair.tool] = stamp_;
        l2_[l2_count_++] = pair.tool;
      }
      if (!pairs_wanted_) continue;
      const LeafPiece& a = tissue_pieces[pair.tissue];
      const LeafPiece& b = tool_pieces[pair.tool];
      // A triangle pair can meet through several leaf pairs only when a triangle has several
      // leaves; with one side sliced it is tested at that side's first meeting leaf, and only
      // when both are sliced does the table of tested pairs decide.
      if (kTableForSlices ? (a.slices > 1 || b.slices > 1) : (a.slices > 1 && b.slices > 1)) {
        test_triangles(tissue, a.triangle, b.triangle, true);
      } else if (b.slices > 1) {
        // Tested at the first slab (chain order) whose sphere meets s1: scanning the earlier slabs
        // nearest first finds a meeting neighbour at once when there is one.
        const std::int32_t* chain = tool_chain_.data() + tool_chain_begin_[b.triangle];
        std::int32_t k = tool_leaf_rank_[static_cast<std::size_t>(pair.tool)] - 1;
        while (k >= 0 && !spheres_meet(s1, tool_spheres[chain[k]], slack)) --k;
        if (k < 0) test_triangles(tissue, a.triangle, b.triangle, false);
      } else if (a.slices > 1) {
        if (first_meeting_leaf(tissue_tree, tissue_spheres, a.triangle, pair.tissue, s2, slack)) {
          test_triangles(tissue, a.triangle, b.triangle, false);
        }
      } else {
        test_triangles(tissue, a.triangle, b.triangle, false);
      }
      continue;
    }
    sphere_tests += 2;
    // Steps 11-17: open the non-leaf sphere, or the larger when neither is a leaf.
    if (!leaf1 && (leaf2 || s1.radius >= s2.radius)) {
      const std::int32_t near = links1.left;
      const std::int32_t far = links1.right;
      const double d_near = length_squared(tissue_spheres[near].center - s2.center);
      const double d_far = length_squared(tissue_spheres[far].center - s2.center);
      const bool swap = d_far < d_near;
      const std::int32_t first = swap ? far : near;
      const std::int32_t second = swap ? near : far;
      const bool meets_near = within_reach(swap ? d_far : d_near, tissue_spheres[first].radius, s2.radius, slack);
      const bool meets_far = within_reach(swap ? d_near : d_far, tissue_spheres[second].radius, s2.radius, slack);
      // Written always, kept only when they meet: no branch on an unpredictable outcome.
      stack[top] = {second, pair.tool};
      top += meets_far;
      stack[top] = {first, pair.tool};
      top += meets_near;
    } else {
      const std::int32_t near = links2.left;
      const std::int32_t far = links2.right;
      const double d_near = length_squared(s1.center - tool_spheres[near].center);
      const double d_far = length_squared(s1.center - tool_spheres[far].center);
      const bool swap = d_far < d_near;
      const std::int32_t first = swap ? far : near;
      const std::int32_t second = swap ? near : far;
      const bool meets_near = within_reach(swap ? d_far : d_near, s1.radius, tool_spheres[first].radius, slack);
      const bool meets_far = within_reach(swap ? d_near : d_far, s1.radius, tool_spheres[second].radius, slack);
      stack[top] = {pair.tissue, second};
      top += meets_far;
      stack[top] = {pair.tissue, first};
      top += meets_near;
    }
  }
  stats_.sphere_tests = sphere_tests;
  stats_.leaf_pairs = leaf_pairs;
  // Sorted on the unique (tissue, tool) key: the same output whatever the walk order.
  std::sort(pairs_.begin(), pairs_.begin() + static_cast<std::ptrdiff_t>(pair_count_));
  return !overflowed_;
}

std::vector<TrianglePair> collide_brute_force(const TriangleMesh& tissue, const TriangleMesh& tool,
                                              const RigidTransform& tool_pose) {
  std::vector<Vec3> world(tool.vertex_count());
  for (std::size_t v = 0; v < world.size(); ++v) world[v] = transform_point(tool_pose, tool.positions[v]);
  const auto box_of = [](const Vec3& a, const Vec3& b, const Vec3& c) {
    return Aabb{glm::min(a, glm::min(b, c)), glm::max(a, glm::max(b, c))};
  };
  std::vector<Aabb> tool_boxes(tool.triangle_count());
  for (std::size_t u = 0; u < tool_boxes.size(); ++u) {
    const Triangle& t = tool.triangles[u];
    tool_boxes[u] = box_of(world[t[0]], world[t[1]], world[t[2]]);
  }
  std::vector<TrianglePair> pairs;
  // Tissue-major, then tool: the output is sorted by construction.
  for (std::uint32_t a = 0; a < tissue.triangle_count(); ++a) {
    const Triangle& ta = tissue.triangles[a];
    const Vec3& p0 = tissue.positions[ta[0]];
    const Vec3& p1 = tissue.positions[ta[1]];
    const Vec3& p2 = tissue.positions[ta[2]];
    const Aabb box = box_of(p0, p1, p2);
    for (std::uint32_t b = 0; b < tool.triangle_count(); ++b) {
      const Aabb& other = tool_boxes[b];
      // Closed boxes that do not meet hold closed triangles that do not meet: exact on coordinates.
      if (box.max.x < other.min.x || other.max.x < box.min.x || box.max.y < other.min.y ||
          other.max.y < box.min.y || box.max.z < other.min.z || other.max.z < box.min.z) {
        continue;
      }
      const Triangle& tb = tool.triangles[b];
      if (triangles_intersect(p0, p1, p2, world[tb[0]], world[tb[1]], world[tb[2]])) pairs.push_back({a, b});
    }
  }
  return pairs;
}

}  // namespace resecto
