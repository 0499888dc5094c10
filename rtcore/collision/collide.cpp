// The dual descent over a tissue tree and a rigid tool tree, and the brute-force baseline it is
// checked and raced against.
#include "rtcore/collision/collide.h"

#include <algorithm>
#include <cmath>

#include "rtcore/base/state_hash.h"
#include "rtcore/geometry/triangle_triangle.h"

namespace resecto {
namespace {

double max_abs(const Vec3& v) { return std::max({std::abs(v.x), std::abs(v.y), std::abs(v.z)}); }

// An upper bound on how much the pose's matrix can lengthen a vector: sqrt of the infinity norm of
// R^T R bounds its spectral norm; exactly 1 (up to rounding) for a rotation.
double stretch_bound(const RigidPose& pose) {
  const auto& r = pose.rotation;
  double worst_row = 0.0;
  for (int i = 0; i < 3; ++i) {
    double row = 0.0;
    for (int j = 0; j < 3; ++j) {
      row += std::abs(r[i][0] * r[j][0] + r[i][1] * r[j][1] + r[i][2] * r[j][2]);
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

namespace {

std::uint64_t fingerprint(const TriangleMesh& mesh) {
  StateHasher hasher;
  hasher.add(std::span<const Vec3>(mesh.positions));
  hasher.add(std::span<const Triangle>(mesh.triangles));
  return hasher.value() | 1u;  // never 0, which means no tool
}

}  // namespace

void Collider::prepare_tool(const TriangleMesh& tool) {
  field_.build(tool);
  field_tool_ = fingerprint(tool);
}

void Collider::prepare(const SphereTree& tissue_tree, const SphereTree& tool_tree, const TriangleMesh& tool) {
  // resize() allocates only when a tree has grown past every size seen before.
  const auto tissue_nodes = static_cast<std::size_t>(tissue_tree.node_capacity());
  const auto tool_nodes = static_cast<std::size_t>(tool_tree.node_capacity());
  tool_vertices_.resize(tool.vertex_count());
  tool_boxes_.resize(tool.triangle_count());
  l1_stamp_.resize(tissue_nodes, 0);
  l1_.resize(tissue_nodes);
  if (method_ == CollisionMethod::kToolField) {
    if (field_tool_ != fingerprint(tool)) prepare_tool(tool);
    // Depth-first over one tree: each step pushes at most two nodes, so the height bounds the stack.
    node_stack_.resize(static_cast<std::size_t>(tissue_tree.links()[tissue_tree.root()].height) + 2);
    near_leaves_.resize(tissue_nodes);  // each leaf is set aside at most once a query
    near_leaf_count_ = 0;
    stack_.resize(static_cast<std::size_t>(tool_tree.links()[tool_tree.root()].height) + 2);
    return;
  }
  tool_spheres_.resize(tool_nodes);
  tool_slabs_.resize(tool_nodes);
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
  l2_stamp_.resize(tool_nodes, 0);
  l2_.resize(tool_nodes);
  const std::int32_t heights = tissue_tree.links()[tissue_tree.root()].height + tool_tree.links()[tool_tree.root()].height;
  // Depth-first: at most three pending pairs per level (a step that opens both nodes pushes four),
  // plus the slots a step's pairs are written to before it is known which are kept.
  stack_.resize(3 * static_cast<std::size_t>(heights) + 8);
}

bool Collider::first_test_of(std::uint32_t tissue_triangle, std::uint32_t tool_triangle) {
  const std::uint64_t key = (static_cast<std::uint64_t>(tissue_triangle) << 32) | tool_triangle;
  if (2 * (tested_count_ + 1) > tested_window_) {
    // The window in use is full: widen it (slots of this query in the old window may now be missed,
    // so a pair may be tested twice; finish_query() drops repeats). At the table's size, test again.
    if (tested_window_ == tested_.size()) return true;
    tested_window_ *= 2;
  }
  // Only the window's first slots are probed: a few thousand pairs stay in cache.
  const std::size_t mask = tested_window_ - 1;
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
  if (!boxes_overlap(triangle_box(p0, p1, p2), tool_boxes_[b])) return;
  exact_test(a, p0, p1, p2, b);
}

void Collider::exact_test(std::uint32_t a, const Vec3& p0, const Vec3& p1, const Vec3& p2, std::uint32_t b) {
  ++stats_.triangle_tests;
  const Triangle& tb = tool_mesh_->triangles[b];
  if (!triangles_intersect(p0, p1, p2, tool_vertices_[tb[0]], tool_vertices_[tb[1]], tool_vertices_[tb[2]])) return;
  if (pair_count_ == pairs_.size()) {
    overflowed_ = true;
    return;
  }
  pairs_[pair_count_++] = {a, b};
}

// ---- Bounds tests ------------------------------------------------------------------------------

namespace {

// The separating-axis test of two nodes' regions (sphere inside slab) along each slab's normal.
// Returns the larger of the two axes' gaps; > 0 is a lower bound on the distance between the regions.
// One lean (the sine between the normals) serves both axes.
[[gnu::always_inline]] inline double slab_gap(const Sphere& a, const Slab& sa, const Sphere& b, const Slab& sb, double slack) {
  const double k = dot(sa.normal, sb.normal);
  const double lean = std::sqrt(std::max(0.0, 1.0 - k * k) + 1e-15);
  // b projected onto a's normal (see project_bound), then a onto b's.
  const double b_along = dot(sa.normal, b.center);
  const double b_rest = b_along - k * dot(sb.normal, b.center);
  const double b_lo = std::max((k >= 0.0 ? k * sb.lo : k * sb.hi) + b_rest - b.radius * lean, b_along - b.radius);
  const double b_hi = std::min((k >= 0.0 ? k * sb.hi : k * sb.lo) + b_rest + b.radius * lean, b_along + b.radius);
  const double a_along = dot(sb.normal, a.center);
  const double a_rest = a_along - k * dot(sa.normal, a.center);
  const double a_lo = std::max((k >= 0.0 ? k * sa.lo : k * sa.hi) + a_rest - a.radius * lean, a_along - a.radius);
  const double a_hi = std::min((k >= 0.0 ? k * sa.hi : k * sa.lo) + a_rest + a.radius * lean, a_along + a.radius);
  return std::max({sa.lo - b_hi, b_lo - sa.hi, sb.lo - a_hi, a_lo - sb.hi}) - slack;
}

}  // namespace

double Collider::gap(std::int32_t tissue_node, std::int32_t tool_node) const {
  const Sphere& a = tissue_tree_->spheres()[static_cast<std::size_t>(tissue_node)];
  const Sphere& b = tool_spheres_[static_cast<std::size_t>(tool_node)];
  const double sphere_gap = length(a.center - b.center) - a.radius - b.radius - slack_;
  if (!slabs_) return sphere_gap;
  return std::max(sphere_gap, slab_gap(a, tissue_tree_->slabs()[static_cast<std::size_t>(tissue_node)], b,
                                       tool_slabs_[static_cast<std::size_t>(tool_node)], slab_slack_));
}

// The descent's test, without the square root of the sphere distance when the spheres decide.
[[gnu::always_inline]] inline bool Collider::bounds_meet(std::int32_t tissue_node, std::int32_t tool_node, double distance2) const {
  const Sphere& a = tissue_tree_->spheres()[static_cast<std::size_t>(tissue_node)];
  const Sphere& b = tool_spheres_[static_cast<std::size_t>(tool_node)];
  if (!within_reach(distance2, a.radius, b.radius, slack_)) return false;
  return !slabs_ || slab_gap(a, tissue_tree_->slabs()[static_cast<std::size_t>(tissue_node)], b,
                             tool_slabs_[static_cast<std::size_t>(tool_node)], slab_slack_) <= 0.0;
}

// ---- The descent --------------------------------------------------------------------------------

bool Collider::begin_query(const SphereTree& tissue_tree, const SphereTree& tool_tree, const TriangleMesh& tool,
                           const RigidPose& tool_pose) {
  pair_count_ = 0;
  l1_count_ = 0;
  l2_count_ = 0;
  // The table's window: four times the last query's count of tested pairs.
  tested_window_ = 256;
  while (tested_window_ < 4 * tested_count_ && tested_window_ < tested_.size()) tested_window_ *= 2;
  tested_window_ = std::min(tested_window_, tested_.size());
  tested_count_ = 0;
  overflowed_ = false;
  stats_ = {};
  if (tissue_tree.empty() || tool_tree.empty()) return false;
  prepare(tissue_tree, tool_tree, tool);
  next_stamp();
  tissue_tree_ = &tissue_tree;
  tool_tree_ = &tool_tree;
  pose_ = tool_pose;
  radius_scale_ = stretch_bound(tool_pose);
  tool_mesh_ = &tool;
  // Place the tool once: its tree and mesh are small next to the work of the descent.
  const std::vector<Sphere>& tool_rest = tool_tree.spheres();
  if (method_ == CollisionMethod::kDualDescent) {
    for (std::size_t n = 0; n < tool_rest.size(); ++n) {
      tool_spheres_[n] = {pose_.apply_point(tool_rest[n].center), tool_rest[n].radius * radius_scale_};
    }
  }
  for (std::size_t v = 0; v < tool_vertices_.size(); ++v) tool_vertices_[v] = pose_.apply_point(tool.positions[v]);
  for (std::size_t u = 0; u < tool_boxes_.size(); ++u) {
    const Triangle& t = tool.triangles[u];
    const Vec3& a = tool_vertices_[t[0]];
    const Vec3& b = tool_vertices_[t[1]];
    const Vec3& c = tool_vertices_[t[2]];
    tool_boxes_[u] = triangle_box(a, b, c);
  }
  // Rounding of transformed centres and of distances is far below this slack; it only ever lets
  // a few more pairs through to the exact test.
  const Sphere& tool_root = tool_rest[tool_tree.root()];
  const double magnitude = max_abs(tool_pose.translation) + max_abs(tool_root.center) + tool_root.radius +
                           max_abs(tissue_tree.spheres()[tissue_tree.root()].center) +
                           tissue_tree.spheres()[tissue_tree.root()].radius;
  slack_ = 1e-12 * magnitude;
  if (method_ == CollisionMethod::kToolField) {
    // Tissue points go to the tool's frame; a stretch of the inverse is allowed for in the radii.
    inverse_rotation_ = glm::inverse(tool_pose.rotation);
    RigidPose inverse_only;
    inverse_only.rotation = inverse_rotation_;
    inverse_scale_ = stretch_bound(inverse_only);
    slabs_ = false;
    return true;
  }
  // A slab keeps its meaning under a rotation only: the pose's deviation from one (R^T R - I) is
  // measured, and beyond rounding the query falls back to the spheres, which allow any stretch.
  const auto& r = tool_pose.rotation;
  double defect = 0.0;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      const double rtr = r[i][0] * r[j][0] + r[i][1] * r[j][1] + r[i][2] * r[j][2];
      defect = std::max(defect, std::abs(rtr - (i == j ? 1.0 : 0.0)));
    }
  }
  slabs_ = slabs_wanted_ && tissue_tree.has_slabs() && tool_tree.has_slabs() && defect <= 1e-12;
  slab_slack_ = 4.0 * slack_ + 4.0 * defect * magnitude;
  if (slabs_) {
    const std::vector<Slab>& rest_slabs = tool_tree.slabs();
    for (std::size_t n = 0; n < rest_slabs.size(); ++n) {
      const Vec3& m = rest_slabs[n].normal;
      const Vec3 normal = tool_pose.apply_vector(m);
      const double offset = dot(normal, tool_pose.translation);
      tool_slabs_[n] = {normal, rest_slabs[n].lo + offset, rest_slabs[n].hi + offset};
    }
  }
  return true;
}

void Collider::visit_leaves(const NodePair& pair) {
  // Steps 4-9: both leaves. Each goes into its list once (the flags make that O(1)).
  if (l1_stamp_[pair.tissue] != stamp_) {
    l1_stamp_[pair.tissue] = stamp_;
    l1_[l1_count_++] = pair.tissue;
  }
  if (l2_stamp_[pair.tool] != stamp_) {
    l2_stamp_[pair.tool] = stamp_;
    l2_[l2_count_++] = pair.tool;
  }
  if (!pairs_wanted_) return;
  const LeafPiece& a = tissue_tree_->pieces()[static_cast<std::size_t>(pair.tissue)];
  const LeafPiece& b = tool_tree_->pieces()[static_cast<std::size_t>(pair.tool)];
  const TriangleMesh& tissue = *tissue_mesh_;
  // A triangle pair can meet through several leaf pairs only when a triangle has several leaves.
  // With the slabs, or with both sides sliced, the table of tested pairs decides. With spheres
  // alone and one side sliced, the pair is tested at that side's first leaf (chain order) whose
  // sphere meets the other's: the descent reaches every leaf pair whose spheres meet.
  if (slabs_ ? (a.slices > 1 || b.slices > 1) : (a.slices > 1 && b.slices > 1)) {
    test_triangles(tissue, a.triangle, b.triangle, true);
    return;
  }
  const Sphere* tissue_spheres = tissue_tree_->spheres().data();
  const Sphere& s1 = tissue_spheres[pair.tissue];
  const Sphere& s2 = tool_spheres_[static_cast<std::size_t>(pair.tool)];
  if (b.slices > 1) {
    // Scanning the earlier slabs nearest first finds a meeting neighbour at once when there is one.
    const std::int32_t* chain = tool_chain_.data() + tool_chain_begin_[b.triangle];
    std::int32_t k = tool_leaf_rank_[static_cast<std::size_t>(pair.tool)] - 1;
    while (k >= 0 && !spheres_meet(s1, tool_spheres_[static_cast<std::size_t>(chain[k])], slack_)) --k;
    if (k < 0) test_triangles(tissue, a.triangle, b.triangle, false);
  } else if (a.slices > 1) {
    if (first_meeting_leaf(*tissue_tree_, tissue_spheres, a.triangle, pair.tissue, s2, slack_)) {
      test_triangles(tissue, a.triangle, b.triangle, false);
    }
  } else {
    test_triangles(tissue, a.triangle, b.triangle, false);
  }
}

void Collider::record(const NodePair& pair, double expiry) {
  if (has_pending_slot_) {
    front_pairs_[pending_slot_] = pair;
    front_expiry_[pending_slot_] = expiry;
    has_pending_slot_ = false;
    return;
  }
  if (front_count_ == front_pairs_.size()) {
    front_overflowed_ = true;  // the walk goes on; the front is rebuilt next call
    return;
  }
  front_pairs_[front_count_] = pair;
  front_expiry_[front_count_++] = expiry;
}

template <bool kRecord>
void Collider::descend(NodePair start) {
  const Sphere* tissue_spheres = tissue_tree_->spheres().data();
  const SphereTreeLinks* tissue_links = tissue_tree_->links().data();
  const Sphere* tool_spheres = tool_spheres_.data();
  const SphereTreeLinks* tool_links = tool_tree_->links().data();
  std::int64_t tests = 1;
  if constexpr (kRecord) {
    const double g = gap(start.tissue, start.tool);
    if (g > 0.0) {
      record(start, travel_ + g);
      stats_.sphere_tests += tests;
      return;
    }
  } else {
    if (!bounds_meet(start.tissue, start.tool,
                     length_squared(tissue_spheres[start.tissue].center - tool_spheres[start.tool].center))) {
      stats_.sphere_tests += tests;
      return;
    }
  }
  // Depth-first with an explicit stack of pairs whose bounds are known to meet: a node opened has
  // both children tested at once, and those that meet are pushed farther first, so the closer is
  // walked first (Figure 11). The walk order depends only on the trees and the pose: deterministic.
  NodePair* const stack = stack_.data();
  std::size_t top = 0;
  stack[top++] = start;
  while (top > 0) {
    const NodePair pair = stack[--top];
    const Sphere& s1 = tissue_spheres[pair.tissue];
    const Sphere& s2 = tool_spheres[pair.tool];
    const SphereTreeLinks& links1 = tissue_links[pair.tissue];
    const SphereTreeLinks& links2 = tool_links[pair.tool];
    const bool leaf1 = links1.left == SphereTree::kNoNode;
    const bool leaf2 = links2.left == SphereTree::kNoNode;
    if (leaf1 && leaf2) {
      ++stats_.leaf_pairs;
      visit_leaves(pair);
      if constexpr (kRecord) record(pair, -1.0);  // leaves that may meet are walked again every call
      continue;
    }
    if constexpr (!kRecord) {
      if (!leaf1 && !leaf2 && s1.radius < 4.0 * s2.radius && s2.radius < 4.0 * s1.radius) {
        // Both internal and of a size (within 4x): both opened at once, their four pairs tested in
        // one step. More tests than opening the larger and then the other (the middle level's
        // pruning is lost), but half the steps, and a step's branches, not its tests, are what the
        // descent pays for (measured: 14-18% faster at 8640 and 138240; within 2x or always, alike).
        tests += 4;
        const std::int32_t a[2] = {links1.left, links1.right};
        const std::int32_t b[2] = {links2.left, links2.right};
        for (int i = 0; i < 2; ++i) {
          for (int j = 0; j < 2; ++j) {
            const NodePair child{a[i], b[j]};
            stack[top] = child;
            top += bounds_meet(child.tissue, child.tool,
                               length_squared(tissue_spheres[child.tissue].center - tool_spheres[child.tool].center));
          }
        }
        continue;
      }
    }
    tests += 2;
    // Steps 11-17: open the non-leaf sphere, or the larger when neither is a leaf.
    NodePair first, second;
    double d_first, d_second;
    if (!leaf1 && (leaf2 || s1.radius >= s2.radius)) {
      const double d_left = length_squared(tissue_spheres[links1.left].center - s2.center);
      const double d_right = length_squared(tissue_spheres[links1.right].center - s2.center);
      const bool swap = d_right < d_left;
      first = {swap ? links1.right : links1.left, pair.tool};
      second = {swap ? links1.left : links1.right, pair.tool};
      d_first = swap ? d_right : d_left;
      d_second = swap ? d_left : d_right;
    } else {
      const double d_left = length_squared(s1.center - tool_spheres[links2.left].center);
      const double d_right = length_squared(s1.center - tool_spheres[links2.right].center);
      const bool swap = d_right < d_left;
      first = {pair.tissue, swap ? links2.right : links2.left};
      second = {pair.tissue, swap ? links2.left : links2.right};
      d_first = swap ? d_right : d_left;
      d_second = swap ? d_left : d_right;
    }
    if constexpr (kRecord) {
      // Separated pairs end the walk here, with their certificates.
      const double g_second = gap(second.tissue, second.tool);
      const double g_first = gap(first.tissue, first.tool);
      if (g_second > 0.0) record(second, travel_ + g_second); else stack[top++] = second;
      if (g_first > 0.0) record(first, travel_ + g_first); else stack[top++] = first;
    } else {
      const bool meets_first = bounds_meet(first.tissue, first.tool, d_first);
      const bool meets_second = bounds_meet(second.tissue, second.tool, d_second);
      // Written always, kept only when they meet: no branch on an unpredictable outcome.
      stack[top] = second;
      top += meets_second;
      stack[top] = first;
      top += meets_first;
    }
  }
  stats_.sphere_tests += tests;
}

// ---- The field method --------------------------------------------------------------------------

double Collider::field_gap(std::int32_t tissue_node) const {
  const Sphere& s = tissue_tree_->spheres()[static_cast<std::size_t>(tissue_node)];
  // A gap in the tool's frame is at least inverse_scale_ times the gap in the world.
  return field_.clearance().ball_clearance(to_tool(s.center), s.radius * inverse_scale_ + slack_) / inverse_scale_;
}

void Collider::visit_field_leaf(std::int32_t leaf, const Vec3& centre, double radius) {
  if (l1_stamp_[static_cast<std::size_t>(leaf)] != stamp_) {
    l1_stamp_[static_cast<std::size_t>(leaf)] = stamp_;
    l1_[l1_count_++] = leaf;
  }
  if (!pairs_wanted_) return;
  const LeafPiece& a = tissue_tree_->pieces()[static_cast<std::size_t>(leaf)];
  // A triangle of several leaves can reach a tool triangle through each: the table decides.
  const bool sliced = a.slices > 1;
  std::span<const std::uint32_t> near;
  if (field_.near(centre, radius, near)) {
    stats_.leaf_pairs += static_cast<std::int64_t>(near.size());
    const TriangleMesh& tissue = *tissue_mesh_;
    const Triangle& ta = tissue.triangles[a.triangle];
    const Vec3& p0 = tissue.positions[ta[0]];
    const Vec3& p1 = tissue.positions[ta[1]];
    const Vec3& p2 = tissue.positions[ta[2]];
    const Aabb box = triangle_box(p0, p1, p2);
    // The tissue triangle in the tool's frame, its box grown by the slack for the transform's rounding.
    const Vec3 t0 = to_tool(p0), t1 = to_tool(p1), t2 = to_tool(p2);
    Aabb local = triangle_box(t0, t1, t2);
    local.min -= Vec3(slack_);
    local.max += Vec3(slack_);
    for (std::uint32_t b : near) {
      // The tissue triangle clear of the tool triangle's box or of its plane (in the tool's frame,
      // where the sheath's long triangles have thin boxes), then the boxes in the world (exact on
      // the coordinates, as brute force's): none can lose a pair.
      const ToolPlane& plane = field_.plane(b);
      if (!boxes_overlap(local, plane.box)) continue;
      const double d0 = dot(plane.normal, t0) - plane.offset;
      const double d1 = dot(plane.normal, t1) - plane.offset;
      const double d2 = dot(plane.normal, t2) - plane.offset;
      const double apart = plane.thickness + slack_;
      if (std::min({d0, d1, d2}) > apart || std::max({d0, d1, d2}) < -apart) continue;
      if (!boxes_overlap(box, tool_boxes_[b])) continue;
      if (sliced && !first_test_of(a.triangle, b)) continue;
      exact_test(a.triangle, p0, p1, p2, b);
    }
    return;
  }
  // A leaf past the field's largest reach (a coarse tissue): the tool's own tree, in its frame.
  const Sphere* tool_spheres = tool_tree_->spheres().data();
  const SphereTreeLinks* tool_links = tool_tree_->links().data();
  const Sphere ball{centre, radius};
  NodePair* const stack = stack_.data();
  std::size_t top = 0;
  stack[top++] = {leaf, tool_tree_->root()};
  while (top > 0) {
    const std::int32_t node = stack[--top].tool;
    ++stats_.sphere_tests;
    if (!spheres_meet(ball, tool_spheres[node], 0.0)) continue;
    const SphereTreeLinks& links = tool_links[node];
    if (links.left == SphereTree::kNoNode) {
      ++stats_.leaf_pairs;
      test_triangles(*tissue_mesh_, a.triangle, tool_tree_->pieces()[static_cast<std::size_t>(node)].triangle, true);
      continue;
    }
    stack[top++] = {leaf, links.right};
    stack[top++] = {leaf, links.left};
  }
}

void Collider::visit_field_leaves() {
  const LeafPiece* pieces = tissue_tree_->pieces().data();
  const Triangle* triangles = tissue_mesh_->triangles.data();
  // Each leaf's data lies scattered (its piece, its triangle's corners, its cell's list): loaded
  // ahead in three steps, the piece and the list's bounds eight leaves ahead, the list itself four
  // ahead (its bounds have arrived by then), the triangle two ahead. The list's own step was 7% on
  // the 60 Hz trajectory at 8640 triangles (benchmarks/results/README.md, session 29).
  constexpr std::size_t kFar = 8, kMiddle = 4, kNear = 2;
  for (std::size_t i = 0; i < near_leaf_count_; ++i) {
    if (i + kFar < near_leaf_count_) {
      const NearLeaf& far = near_leaves_[i + kFar];
      __builtin_prefetch(pieces + far.leaf);
      field_.prefetch_near(far.centre, far.radius);
    }
    if (i + kMiddle < near_leaf_count_) {
      const NearLeaf& middle = near_leaves_[i + kMiddle];
      field_.prefetch_near_list(middle.centre, middle.radius);
    }
    if (i + kNear < near_leaf_count_) __builtin_prefetch(triangles + pieces[near_leaves_[i + kNear].leaf].triangle);
    const NearLeaf& leaf = near_leaves_[i];
    visit_field_leaf(leaf.leaf, leaf.centre, leaf.radius);
  }
  near_leaf_count_ = 0;
}

template <bool kRecord>
void Collider::descend_field(std::int32_t start) {
  const Sphere* spheres = tissue_tree_->spheres().data();
  const SphereTreeLinks* links = tissue_tree_->links().data();
  const ToolClearanceGrid& clearance = field_.clearance();
  std::int32_t* const stack = node_stack_.data();
  std::size_t top = 0;
  stack[top++] = start;
  std::int64_t tests = 0;
  // Each node is placed in the tool's frame and tested once against the tool's clearance: no node
  // pairs, so the work follows the tissue's spheres near the tool, not their products with the tool's.
  while (top > 0) {
    const std::int32_t node = stack[--top];
    ++tests;
    const Sphere& s = spheres[node];
    const Vec3 centre = to_tool(s.center);
    const double radius = s.radius * inverse_scale_ + slack_;
    if constexpr (kRecord) {
      const double g = clearance.ball_clearance(centre, radius);
      if (g > 0.0) {
        record({node, SphereTree::kNoNode}, travel_ + g / inverse_scale_);
        continue;
      }
    } else {
      if (!clearance.ball_may_touch(centre, radius)) continue;
    }
    const SphereTreeLinks& l = links[node];
    if (l.left == SphereTree::kNoNode) {
      near_leaves_[near_leaf_count_++] = {centre, radius, node};
      if constexpr (kRecord) record({node, SphereTree::kNoNode}, -1.0);  // walked again every call
      continue;
    }
    // The left child is next and usually the next node in memory (depth-first numbering); the right
    // waits on the stack, so its loads are started now.
    __builtin_prefetch(spheres + l.right);
    __builtin_prefetch(links + l.right);
    stack[top++] = l.right;
    stack[top++] = l.left;
  }
  stats_.sphere_tests += tests;
}

void Collider::finish_query() {
  // Sorted on the (tissue, tool) key, each once: the same output whatever the walk order.
  const auto end = pairs_.begin() + static_cast<std::ptrdiff_t>(pair_count_);
  std::sort(pairs_.begin(), end);
  pair_count_ = static_cast<std::size_t>(std::unique(pairs_.begin(), end) - pairs_.begin());
}

bool Collider::collide(const SphereTree& tissue_tree, const TriangleMesh& tissue, const SphereTree& tool_tree,
                       const TriangleMesh& tool, const RigidPose& tool_pose) {
  if (!begin_query(tissue_tree, tool_tree, tool, tool_pose)) return true;
  tissue_mesh_ = &tissue;
  walk_subtree(tissue_tree.root());
  finish_query();
  return !overflowed_;
}

void Collider::walk_subtree(std::int32_t start) {
  if (method_ == CollisionMethod::kToolField) {
    descend_field<false>(start);
    visit_field_leaves();
  } else {
    descend<false>({start, tool_tree_->root()});
  }
}

bool Collider::collide_claimed(const SphereTree& tissue_tree, const TriangleMesh& tissue, const SphereTree& tool_tree,
                               const TriangleMesh& tool, const RigidPose& tool_pose, std::span<const std::int32_t> starts,
                               std::atomic<std::uint32_t>& next) {
  if (!begin_query(tissue_tree, tool_tree, tool, tool_pose)) return true;
  tissue_mesh_ = &tissue;
  // A subtree's leaves are visited as soon as it is walked, so a claim is the whole of its work.
  for (std::uint32_t k = next.fetch_add(1, std::memory_order_relaxed); k < starts.size(); k = next.fetch_add(1, std::memory_order_relaxed)) {
    walk_subtree(starts[k]);
  }
  finish_query();
  return !overflowed_;
}

void Collider::reserve_front(std::int32_t max_front) {
  front_pairs_.resize(static_cast<std::size_t>(std::max(max_front, 1)));
  front_expiry_.resize(front_pairs_.size());
  front_valid_ = false;
}

bool Collider::collide_sequence(const SphereTree& tissue_tree, const TriangleMesh& tissue, const SphereTree& tool_tree,
                                const TriangleMesh& tool, const RigidPose& tool_pose, double tissue_travel_m,
                                std::span<const std::int32_t> starts) {
  if (!begin_query(tissue_tree, tool_tree, tool, tool_pose)) {
    front_valid_ = false;
    return true;
  }
  tissue_mesh_ = &tissue;
  const bool field = method_ == CollisionMethod::kToolField;
  // The dual descent's certificates need the slabs' rigid pose; the field's hold for any pose.
  const bool certifiable = field || slabs_;
  const bool same_trees = front_tissue_tree_ == &tissue_tree && front_tool_tree_ == &tool_tree &&
                          front_tissue_version_ == tissue_tree.structure_version() &&
                          front_tool_version_ == tool_tree.structure_version() &&
                          previous_tool_vertices_.size() == tool_vertices_.size();
  bool fresh = !front_valid_ || !same_trees || !certifiable || tissue_travel_m < last_tissue_travel_ ||
               front_count_ > 2 * fresh_front_count_ + 1024;
  if (!fresh) {
    // How far the tool moved since the last call: its largest vertex displacement (a point of a
    // triangle moves by an affine mix of its corners' moves), rounded up.
    double moved2 = 0.0;
    for (std::size_t v = 0; v < tool_vertices_.size(); ++v) {
      moved2 = std::max(moved2, length_squared(tool_vertices_[v] - previous_tool_vertices_[v]));
    }
    travel_ += std::sqrt(moved2) * (1.0 + 1e-9) + slack_ + (tissue_travel_m - last_tissue_travel_) * (1.0 + 1e-9);
    renew_front(tissue_tree, tool_tree);
  } else {
    if (front_pairs_.empty() || front_overflowed_) {
      // Grown only here, off the steady state: a front that did not fit gets twice the room.
      reserve_front(static_cast<std::int32_t>(std::max<std::size_t>(1 << 14, 2 * front_pairs_.size())));
    }
    front_count_ = 0;
    front_overflowed_ = false;
    travel_ = 0.0;
    const std::int32_t root = tissue_tree.root();
    for (const std::int32_t start : starts.empty() ? std::span<const std::int32_t>(&root, 1) : starts) {
      if (field) {
        descend_field<true>(start);
      } else {
        descend<true>({start, tool_tree.root()});
      }
    }
    fresh_front_count_ = front_count_;
  }
  if (field) visit_field_leaves();
  front_valid_ = !front_overflowed_ && certifiable;
  front_tissue_tree_ = &tissue_tree;
  front_tool_tree_ = &tool_tree;
  front_tissue_version_ = tissue_tree.structure_version();
  front_tool_version_ = tool_tree.structure_version();
  last_tissue_travel_ = tissue_travel_m;
  previous_tool_vertices_.assign(tool_vertices_.begin(), tool_vertices_.end());
  finish_query();
  return !overflowed_;
}

// Every cached pair whose certificate ran out is tested again: most are still apart and get a new
// certificate in place; the rest are walked from where the last walk stopped.
void Collider::renew_front(const SphereTree& tissue_tree, const SphereTree& tool_tree) {
  const bool field = method_ == CollisionMethod::kToolField;
  const std::size_t cached = front_count_;
  const Sphere* tissue_spheres = tissue_tree.spheres().data();
  const Slab* tissue_slabs = tissue_tree.slabs().data();
  const SphereTreeLinks* tissue_links = tissue_tree.links().data();
  constexpr std::size_t kAhead = 16;  // the cached pairs lie scattered over the tissue's arrays
  for (std::size_t i = 0; i < cached; ++i) {
    if (i + kAhead < cached) {
      const NodePair ahead = front_pairs_[i + kAhead];
      __builtin_prefetch(tissue_spheres + ahead.tissue);
      __builtin_prefetch(tissue_links + ahead.tissue);
      if (!field) {
        __builtin_prefetch(tissue_slabs + ahead.tissue);
        __builtin_prefetch(tool_spheres_.data() + ahead.tool);
        __builtin_prefetch(tool_slabs_.data() + ahead.tool);
      }
    }
    if (front_expiry_[i] > travel_) continue;
    ++stats_.front_renewed;
    const NodePair pair = front_pairs_[i];
    const bool leaves = tissue_tree.is_leaf(pair.tissue) && (field || tool_tree.is_leaf(pair.tool));
    if (!leaves) {
      ++stats_.sphere_tests;
      const double g = field ? field_gap(pair.tissue) : gap(pair.tissue, pair.tool);
      if (g > 0.0) {
        front_expiry_[i] = travel_ + g;
        continue;
      }
    }
    pending_slot_ = i;
    has_pending_slot_ = true;
    if (field) {
      descend_field<true>(pair.tissue);
    } else {
      descend<true>(pair);
    }
    has_pending_slot_ = false;
  }
  stats_.front_kept = static_cast<std::int64_t>(cached) - stats_.front_renewed;
}

std::vector<TrianglePair> collide_brute_force(const TriangleMesh& tissue, const TriangleMesh& tool,
                                              const RigidPose& tool_pose) {
  std::vector<Vec3> world(tool.vertex_count());
  for (std::size_t v = 0; v < world.size(); ++v) world[v] = tool_pose.apply_point(tool.positions[v]);
  std::vector<Aabb> tool_boxes(tool.triangle_count());
  for (std::size_t u = 0; u < tool_boxes.size(); ++u) {
    const Triangle& t = tool.triangles[u];
    tool_boxes[u] = triangle_box(world[t[0]], world[t[1]], world[t[2]]);
  }
  std::vector<TrianglePair> pairs;
  // Tissue-major, then tool: the output is sorted by construction.
  for (std::uint32_t a = 0; a < tissue.triangle_count(); ++a) {
    const Triangle& ta = tissue.triangles[a];
    const Vec3& p0 = tissue.positions[ta[0]];
    const Vec3& p1 = tissue.positions[ta[1]];
    const Vec3& p2 = tissue.positions[ta[2]];
    const Aabb box = triangle_box(p0, p1, p2);
    for (std::uint32_t b = 0; b < tool.triangle_count(); ++b) {
      // Closed boxes that do not meet hold closed triangles that do not meet: exact on coordinates.
      if (!boxes_overlap(box, tool_boxes[b])) continue;
      const Triangle& tb = tool.triangles[b];
      if (triangles_intersect(p0, p1, p2, world[tb[0]], world[tb[1]], world[tb[2]])) pairs.push_back({a, b});
    }
  }
  return pairs;
}

}  // namespace resecto
