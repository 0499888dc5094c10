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

}  // namespace

void Collider::reserve(std::int32_t max_pairs, std::int32_t max_tested_pairs) {
  pairs_.resize(static_cast<std::size_t>(std::max(max_pairs, 1)));
  std::size_t table = 64;
  while (table < 2 * static_cast<std::size_t>(std::max(max_tested_pairs, 1))) table *= 2;
  tested_keys_.assign(table, 0);
  tested_stamp_.assign(table, 0);
}

void Collider::next_stamp() {
  if (++stamp_ == 0) {  // wrapped: forget every old mark once
    for (auto* marks : {&tool_center_stamp_, &tool_vertex_stamp_, &l1_stamp_, &l2_stamp_, &tested_stamp_}) {
      std::fill(marks->begin(), marks->end(), 0u);
    }
    stamp_ = 1;
  }
}

void Collider::prepare(const SphereTree& tissue_tree, const SphereTree& tool_tree, const TriangleMesh& tool) {
  // resize() allocates only when a tree has grown past every size seen before.
  const auto tissue_nodes = static_cast<std::size_t>(tissue_tree.node_capacity());
  const auto tool_nodes = static_cast<std::size_t>(tool_tree.node_capacity());
  tool_centers_.resize(tool_nodes);
  tool_center_stamp_.resize(tool_nodes, 0);
  tool_vertices_.resize(tool.vertex_count());
  tool_vertex_stamp_.resize(tool.vertex_count(), 0);
  l1_stamp_.resize(tissue_nodes, 0);
  l1_.resize(tissue_nodes);
  l2_stamp_.resize(tool_nodes, 0);
  l2_.resize(tool_nodes);
  const std::int32_t heights = tissue_tree.links()[tissue_tree.root()].height + tool_tree.links()[tool_tree.root()].height;
  stack_.resize(static_cast<std::size_t>(heights) + 2);
}

const Vec3& Collider::tool_center(const SphereTree& tool_tree, std::int32_t node) {
  if (tool_center_stamp_[node] != stamp_) {
    tool_center_stamp_[node] = stamp_;
    tool_centers_[node] = transform_point(pose_, tool_tree.spheres()[node].center);
  }
  return tool_centers_[node];
}

const Vec3& Collider::tool_vertex(const TriangleMesh& tool, std::uint32_t v) {
  if (tool_vertex_stamp_[v] != stamp_) {
    tool_vertex_stamp_[v] = stamp_;
    tool_vertices_[v] = transform_point(pose_, tool.positions[v]);
  }
  return tool_vertices_[v];
}

bool Collider::first_test_of(std::uint32_t tissue_triangle, std::uint32_t tool_triangle) {
  const std::uint64_t key = (static_cast<std::uint64_t>(tissue_triangle) << 32) | tool_triangle;
  const std::size_t mask = tested_keys_.size() - 1;
  if (2 * (tested_count_ + 1) > tested_keys_.size()) {
    overflowed_ = true;  // table too full to probe: test again rather than risk a lost pair
    return true;
  }
  std::size_t slot = static_cast<std::size_t>((key * 0x9E3779B97F4A7C15ull) >> 20) & mask;
  while (tested_stamp_[slot] == stamp_) {
    if (tested_keys_[slot] == key) return false;
    slot = (slot + 1) & mask;
  }
  tested_stamp_[slot] = stamp_;
  tested_keys_[slot] = key;
  ++tested_count_;
  return true;
}

void Collider::test_triangles(const TriangleMesh& tissue, const TriangleMesh& tool, std::uint32_t a, std::uint32_t b) {
  if (!first_test_of(a, b)) return;  // another leaf pair of these two triangles got here first
  ++stats_.triangle_tests;
  const Triangle& ta = tissue.triangles[a];
  const Triangle& tb = tool.triangles[b];
  if (!triangles_intersect(tissue.positions[ta[0]], tissue.positions[ta[1]], tissue.positions[ta[2]],
                           tool_vertex(tool, tb[0]), tool_vertex(tool, tb[1]), tool_vertex(tool, tb[2]))) {
    return;
  }
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
  // Rounding of transformed centres and of distances is far below this slack; it only ever lets
  // a few more sphere pairs through to the exact test.
  const Sphere& tool_root = tool_tree.spheres()[tool_tree.root()];
  const double slack = 1e-12 * (max_abs(tool_pose.translation) + max_abs(tool_root.center) + tool_root.radius +
                                max_abs(tissue_tree.spheres()[tissue_tree.root()].center));

  const std::vector<Sphere>& tissue_spheres = tissue_tree.spheres();
  const std::vector<SphereTreeLinks>& tissue_links = tissue_tree.links();
  const std::vector<Sphere>& tool_spheres = tool_tree.spheres();
  const std::vector<SphereTreeLinks>& tool_links = tool_tree.links();

  // Depth-first with an explicit stack; children are pushed farther first so the closer one is
  // walked first (Figure 11). The walk order depends only on the trees and the pose: deterministic.
  std::size_t top = 0;
  stack_[top++] = {tissue_tree.root(), tool_tree.root()};
  while (top > 0) {
    const NodePair pair = stack_[--top];
    const Sphere& s1 = tissue_spheres[pair.tissue];
    const Vec3& c2 = tool_center(tool_tree, pair.tool);
    const double r2 = tool_spheres[pair.tool].radius * radius_scale_;
    ++stats_.sphere_tests;
    const double reach = s1.radius + r2 + slack;
    if (length_squared(s1.center - c2) > reach * reach) continue;

    const bool leaf1 = tissue_links[pair.tissue].left == SphereTree::kNoNode;
    const bool leaf2 = tool_links[pair.tool].left == SphereTree::kNoNode;
    if (leaf1 && leaf2) {
      // Steps 4-9: both leaves. Each goes into its list once (the flags make that O(1)).
      if (l1_stamp_[pair.tissue] != stamp_) {
        l1_stamp_[pair.tissue] = stamp_;
        l1_[l1_count_++] = pair.tissue;
      }
      if (l2_stamp_[pair.tool] != stamp_) {
        l2_stamp_[pair.tool] = stamp_;
        l2_[l2_count_++] = pair.tool;
      }
      test_triangles(tissue, tool, tissue_tree.pieces()[pair.tissue].triangle, tool_tree.pieces()[pair.tool].triangle);
      continue;
    }
    // Steps 11-17: open the non-leaf sphere, or the larger when neither is a leaf.
    if (!leaf1 && (leaf2 || s1.radius >= r2)) {
      std::int32_t near = tissue_links[pair.tissue].left;
      std::int32_t far = tissue_links[pair.tissue].right;
      if (length_squared(tissue_spheres[far].center - c2) < length_squared(tissue_spheres[near].center - c2)) {
        std::swap(near, far);
      }
      stack_[top++] = {far, pair.tool};
      stack_[top++] = {near, pair.tool};
    } else {
      std::int32_t near = tool_links[pair.tool].left;
      std::int32_t far = tool_links[pair.tool].right;
      if (length_squared(tool_center(tool_tree, far) - s1.center) <
          length_squared(tool_center(tool_tree, near) - s1.center)) {
        std::swap(near, far);
      }
      stack_[top++] = {pair.tissue, far};
      stack_[top++] = {pair.tissue, near};
    }
  }
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
