// Sphere-tree construction (top-down, principal-component splits), bottom-up refit, and O(log n)
// insertion and removal of triangles, all over one flat node array with a free list.
#include "rtcore/collision/sphere_tree.h"

#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>
#include <limits>
#include <span>

#include "rtcore/collision/sphere_refit_kernel.h"

namespace resecto {
namespace {

// A sphere around points: the better of the box centre and the centroid.
template <std::size_t N>
Sphere sphere_around(const std::array<Vec3, N>& points) {
  Vec3 lo = points[0];
  Vec3 hi = points[0];
  Vec3 sum{0.0};
  for (const Vec3& p : points) {
    lo = glm::min(lo, p);
    hi = glm::max(hi, p);
    sum += p;
  }
  const std::array<Vec3, 2> centers{0.5 * (lo + hi), sum / static_cast<double>(N)};
  Sphere best{centers[0], INFINITY};
  for (const Vec3& c : centers) {
    double r2 = 0.0;
    for (const Vec3& p : points) r2 = std::max(r2, length_squared(p - c));
    const double r = std::sqrt(r2);
    if (r < best.radius) best = {c, r};
  }
  return inflated_sphere(best.center, best.radius);
}

// A tight sphere around a triangle, O(1): the sphere on its longest edge when that holds the third
// corner (an obtuse or right triangle: then it is the smallest), else the circumsphere. The radius
// is measured from the rounded centre to every corner, so rounding can only loosen, never uncover.
Sphere triangle_sphere(const Vec3& a, const Vec3& b, const Vec3& c) {
  const double ab = length_squared(b - a);
  const double bc = length_squared(c - b);
  const double ca = length_squared(a - c);
  Vec3 center;
  // The longest edge's midpoint, and the corner opposite it.
  const Vec3* far = &c;
  center = 0.5 * (a + b);
  double half2 = 0.25 * ab;
  if (bc >= ab && bc >= ca) {
    center = 0.5 * (b + c), half2 = 0.25 * bc, far = &a;
  } else if (ca >= ab && ca >= bc) {
    center = 0.5 * (c + a), half2 = 0.25 * ca, far = &b;
  }
  if (length_squared(*far - center) > half2) {
    const Vec3 u = b - a;
    const Vec3 v = c - a;
    const Vec3 w = cross(u, v);
    const double w2 = length_squared(w);
    if (w2 > 0.0) center = a + (cross(w, u) * length_squared(v) + cross(v, w) * length_squared(u)) / (2.0 * w2);
  }
  const double r2 = std::max({length_squared(a - center), length_squared(b - center), length_squared(c - center)});
  return inflated_sphere(center, std::sqrt(r2));
}

double max_abs(const Vec3& v) { return std::max({std::abs(v.x), std::abs(v.y), std::abs(v.z)}); }

}  // namespace

Slab SphereTree::triangle_slab(const TriangleMesh& mesh, std::uint32_t t, const Sphere& sphere) {
  const Triangle& tri = mesh.triangles[t];
  const Vec3& a = mesh.positions[tri[0]];
  const Vec3& b = mesh.positions[tri[1]];
  const Vec3& c = mesh.positions[tri[2]];
  const Vec3 n = cross(b - a, c - a);
  const double n_length = length(n);
  Slab slab;
  if (!(n_length > 0.0) || !std::isfinite(n_length)) {  // no plane: the sphere's extent along z
    slab.lo = sphere.center.z - sphere.radius;
    slab.hi = sphere.center.z + sphere.radius;
    return slab;
  }
  slab.normal = n / n_length;
  const double da = dot(slab.normal, a);
  const double db = dot(slab.normal, b);
  const double dc = dot(slab.normal, c);
  // Each dot is off by a few ulps of the coordinates' size; the pad is far above that.
  const double pad = 1e-12 * std::max({max_abs(a), max_abs(b), max_abs(c)});
  slab.lo = std::min({da, db, dc}) - pad;
  slab.hi = std::max({da, db, dc}) + pad;
  return slab;
}

Slab SphereTree::merge_slabs(const Sphere& a, const Slab& sa, const Sphere& b, const Slab& sb) {
  Vec3 axis = sa.normal + sb.normal;
  const double axis_length = length(axis);
  // Children facing opposite ways have no useful common slab; any unit axis stays correct.
  axis = axis_length > 1e-3 ? axis / axis_length : sa.normal;
  double lo_a, hi_a, lo_b, hi_b;
  project_bound(a, sa, axis, lo_a, hi_a);
  project_bound(b, sb, axis, lo_b, hi_b);
  const double pad = 1e-12 * (max_abs(a.center) + a.radius + max_abs(b.center) + b.radius + std::abs(sa.lo) +
                              std::abs(sa.hi) + std::abs(sb.lo) + std::abs(sb.hi));
  return {axis, std::min(lo_a, lo_b) - pad, std::max(hi_a, hi_b) + pad};
}

int SphereTree::slice_count(const TriangleMesh& mesh, std::uint32_t t, std::uint8_t& apex) {
  return slice_count(mesh, t, apex, kSliceAspect);
}

int SphereTree::slice_count(const TriangleMesh& mesh, std::uint32_t t, std::uint8_t& apex, double aspect) {
  const Triangle& tri = mesh.triangles[t];
  const std::array<Vec3, 3> v{mesh.positions[tri[0]], mesh.positions[tri[1]], mesh.positions[tri[2]]};
  // The edge opposite vertex i runs from v[i+1] to v[i+2]; slabs are cut parallel to the shortest.
  double shortest = INFINITY;
  for (int i = 0; i < 3; ++i) {
    const double edge = length(v[(i + 2) % 3] - v[(i + 1) % 3]);
    if (edge < shortest) {
      shortest = edge;
      apex = static_cast<std::uint8_t>(i);
    }
  }
  const Vec3 base = v[(apex + 2) % 3] - v[(apex + 1) % 3];
  if (!(shortest > 0.0)) return 1;
  const double height = length(cross(base, v[apex] - v[(apex + 1) % 3])) / shortest;
  const double slices = std::ceil(height / (aspect * shortest));
  // Edges past 1e154 square to infinity and the ratio to NaN, which std::clamp passes through (and
  // casting it is undefined): such a triangle keeps one leaf, so the leaf count stays bounded.
  if (!(slices >= 1.0)) return 1;
  return static_cast<int>(std::min(slices, static_cast<double>(kMaxSlices)));
}

Sphere SphereTree::piece_sphere(const TriangleMesh& mesh, const LeafPiece& piece) {
  const Triangle& tri = mesh.triangles[piece.triangle];
  const Vec3& b = mesh.positions[tri[piece.apex]];
  const Vec3& x = mesh.positions[tri[(piece.apex + 1) % 3]];
  const Vec3& y = mesh.positions[tri[(piece.apex + 2) % 3]];
  if (piece.slices == 1) return triangle_sphere(b, x, y);
  const SliceOperands operands = slice_operands(mesh, piece);
  return slice_sphere(b, x, y, operands.t0, operands.t1);
}

Sphere SphereTree::slice_sphere(const Vec3& b, const Vec3& x, const Vec3& y, double t0, double t1) {
  // The slab between the lines at t0 and t1 (t: the weight of the apex) is the hull of these four.
  return sphere_around(std::array<Vec3, 4>{x * (1.0 - t0) + b * t0, y * (1.0 - t0) + b * t0, x * (1.0 - t1) + b * t1, y * (1.0 - t1) + b * t1});
}

SliceOperands SphereTree::slice_operands(const TriangleMesh& mesh, const LeafPiece& piece) {
  const Triangle& tri = mesh.triangles[piece.triangle];
  return {{tri[piece.apex], tri[(piece.apex + 1) % 3], tri[(piece.apex + 2) % 3]},
          static_cast<double>(piece.slice) / piece.slices,
          static_cast<double>(piece.slice + 1) / piece.slices};
}

std::int32_t SphereTree::allocate_node() {
  ++live_nodes_;
  if (free_list_ != kNoNode) {
    const std::int32_t node = free_list_;
    free_list_ = links_[node].left;
    links_[node] = SphereTreeLinks{};
    next_leaf_[node] = kNoNode;
    return node;
  }
  spheres_.emplace_back();
  slabs_.emplace_back();
  leans_.emplace_back();
  links_.emplace_back();
  pieces_.emplace_back();
  next_leaf_.push_back(kNoNode);
  return static_cast<std::int32_t>(links_.size()) - 1;
}

void SphereTree::free_node(std::int32_t node) {
  --live_nodes_;
  links_[node] = SphereTreeLinks{kNoNode, free_list_, kNoNode, -1};  // height -1 marks a free slot
  free_list_ = node;
}

std::int32_t SphereTree::free_node_count() const {
  std::int32_t count = 0;
  for (std::int32_t n = free_list_; n != kNoNode; n = links_[n].left) ++count;
  return count;
}

void SphereTree::add_triangle_leaves(const TriangleMesh& mesh, std::uint32_t t, bool insert) {
  if (first_leaf_.size() <= t) first_leaf_.resize(t + 1, kNoNode);
  assert(first_leaf_[t] == kNoNode && "triangle already in the tree");
  std::uint8_t apex = 0;
  const int slices = slice_count(mesh, t, apex, slice_aspect_);
  for (int s = slices - 1; s >= 0; --s) {  // pushed front-first so the chain runs slice 0, 1, ...
    const std::int32_t leaf = allocate_node();
    pieces_[leaf] = {t, static_cast<std::uint16_t>(s), static_cast<std::uint16_t>(slices), apex};
    spheres_[leaf] = piece_sphere(mesh, pieces_[leaf]);
    if (slabs_kept_) slabs_[leaf] = triangle_slab(mesh, t, spheres_[leaf]);
    next_leaf_[leaf] = first_leaf_[t];
    first_leaf_[t] = leaf;
    ++leaf_count_;
    if (insert) insert_leaf(leaf);
  }
}

// ---- Build ------------------------------------------------------------------------------------

void SphereTree::build(const TriangleMesh& mesh) {
  build_triangles_.resize(mesh.triangle_count());
  for (std::uint32_t t = 0; t < build_triangles_.size(); ++t) build_triangles_[t] = t;
  start_build(mesh);
  continue_build(std::numeric_limits<std::int64_t>::max());
}

void SphereTree::rebuild(const TriangleMesh& mesh) {
  begin_build(mesh, *this);
  continue_build(std::numeric_limits<std::int64_t>::max());
}

void SphereTree::begin_build(const TriangleMesh& mesh, const SphereTree& covered) {
  build_triangles_.clear();
  for (std::uint32_t t = 0; t < covered.first_leaf_.size(); ++t) {
    if (covered.first_leaf_[t] != kNoNode) build_triangles_.push_back(t);
  }
  start_build(mesh);
}

void SphereTree::reserve(std::int32_t max_nodes, std::uint32_t max_triangles, std::size_t max_vertices) {
  const auto nodes = static_cast<std::size_t>(std::max(max_nodes, 1));
  fitted_positions_.reserve(max_vertices);
  vertex_slot_begin_.reserve(max_vertices + 1);
  slack_vertices_.reserve(max_vertices);
  vertex_slots_.reserve(3 * nodes);
  for (auto* bits : {&moved_slot_bits_, &dirty_node_bits_}) bits->reserve(nodes / 64 + 1);
  for (auto* list : {&dirty_nodes_, &dirty_by_height_}) list->reserve(nodes);
  spheres_.reserve(nodes);
  links_.reserve(nodes);
  pieces_.reserve(nodes);
  next_leaf_.reserve(nodes);
  refit_leaves_.reserve(nodes);
  refit_internal_.reserve(nodes);
  for (auto* list : {&whole_leaves_, &sliced_leaves_, &merge_order_, &block_top_, &block_nodes_, &block_walk_}) list->reserve(nodes);
  whole_corners_.reserve(nodes);
  sliced_operands_.reserve(nodes);
  merge_children_.reserve(nodes);
  refit_blocks_.reserve(nodes);
  merge_group_ends_.reserve(nodes);
  height_slots_.reserve(64);
  stack_.reserve(nodes);
  first_leaf_.reserve(max_triangles);
  build_triangles_.reserve(max_triangles);
  // A rebuild's leaf records: at most one leaf per node.
  build_leaves_.reserve(nodes);
  build_pieces_.reserve(nodes);
  build_slabs_.reserve(nodes);
  build_leaf_nodes_.reserve(nodes);
  build_tasks_.reserve(nodes);
}

// The leaves are made first, as records apart from the tree (their piece, sphere and slab); the
// top-down build then partitions those records in place and numbers the nodes as it reaches them,
// a parent before its left subtree and that before its right one. That is the depth-first layout
// the descent and refit want, with no renumbering pass, and every pass reads the records in a row.
// The build runs from a stack of tasks rather than by recursion, so that it can stop after a given
// amount of work and go on at the next call (continue_build).
void SphereTree::start_build(const TriangleMesh& mesh) {
  ++structure_version_;
  slabs_kept_ = slabs_wanted_;
  build_leaves_.clear();
  build_pieces_.clear();
  build_slabs_.clear();
  for (const std::uint32_t t : build_triangles_) {
    std::uint8_t apex = 0;
    const int slices = slice_count(mesh, t, apex, slice_aspect_);
    for (int s = slices - 1; s >= 0; --s) {  // the order the chains are pushed in below
      const LeafPiece piece{t, static_cast<std::uint16_t>(s), static_cast<std::uint16_t>(slices), apex};
      const Sphere sphere = piece_sphere(mesh, piece);
      build_leaves_.push_back({sphere, static_cast<std::int32_t>(build_pieces_.size())});
      build_pieces_.push_back(piece);
      if (slabs_kept_) build_slabs_.push_back(triangle_slab(mesh, t, sphere));
    }
  }
  leaf_count_ = static_cast<std::int32_t>(build_leaves_.size());
  live_nodes_ = leaf_count_ > 0 ? 2 * leaf_count_ - 1 : 0;
  const auto nodes = static_cast<std::size_t>(live_nodes_);
  spheres_.resize(nodes);
  slabs_.resize(nodes);
  leans_.assign(nodes, Lean{});  // the root keeps the default; every other is set by its parent
  links_.resize(nodes);
  pieces_.assign(nodes, LeafPiece{});
  next_leaf_.assign(nodes, kNoNode);
  build_leaf_nodes_.resize(build_leaves_.size());
  first_leaf_.assign(mesh.triangle_count(), kNoNode);
  free_list_ = kNoNode;
  root_ = kNoNode;
  build_mesh_ = &mesh;
  next_build_node_ = 0;
  build_tasks_.clear();
  if (leaf_count_ > 0) build_tasks_.push_back({0, leaf_count_, kNoNode, BuildTask::kLeftChild});
}

void SphereTree::abandon_build() {
  if (build_mesh_ == nullptr) return;
  build_mesh_ = nullptr;
  build_tasks_.clear();
  root_ = kNoNode;
  leaf_count_ = live_nodes_ = 0;
  spheres_.clear();
  links_.clear();
  slabs_.clear();
  leans_.clear();
  pieces_.clear();
  next_leaf_.clear();
  std::fill(first_leaf_.begin(), first_leaf_.end(), kNoNode);
  order_dirty_ = true;
  applied_slack_ = 0.0;
  fitted_ = false;
}

bool SphereTree::continue_build(std::int64_t work) {
  if (build_mesh_ == nullptr) return true;  // no build under way
  std::int64_t done = 0;
  while (!build_tasks_.empty() && done < work) {
    const BuildTask task = build_tasks_.back();
    build_tasks_.pop_back();
    BuildLeaf* first = build_leaves_.data() + task.first;
    BuildLeaf* last = build_leaves_.data() + task.last;
    if (task.kind == BuildTask::kFinish) {
      finish_node(task.node, first, last);
      done += slabs_kept_ ? task.last - task.first : 1;
    } else {
      start_node(task, first, last);
      done += task.last - task.first;
    }
  }
  if (!build_tasks_.empty()) return false;
  if (leaf_count_ > 0) root_ = 0;
  build_mesh_ = nullptr;
  // Each triangle's chain runs slice 0, 1, ...: pushed front-first, in the order the records were made.
  for (std::size_t r = 0; r < build_pieces_.size(); ++r) {
    const std::int32_t leaf = build_leaf_nodes_[r];
    const std::uint32_t t = build_pieces_[r].triangle;
    next_leaf_[leaf] = first_leaf_[t];
    first_leaf_[t] = leaf;
  }
  order_dirty_ = true;
  applied_slack_ = 0.0;  // built tight, before quality() measures it
  fitted_ = false;
  built_mean_internal_radius_ = quality().mean_internal_radius;
  return true;
}

void SphereTree::start_node(const BuildTask& task, BuildLeaf* first, BuildLeaf* last) {
  const std::int32_t node = next_build_node_++;
  const std::int32_t parent = task.node;
  links_[node] = {parent, kNoNode, kNoNode, 0};
  if (parent != kNoNode) (task.kind == BuildTask::kRightChild ? links_[parent].right : links_[parent].left) = node;
  const std::ptrdiff_t count = last - first;
  if (count == 1) {
    const auto record = static_cast<std::size_t>(first->record);
    spheres_[node] = first->sphere;
    if (slabs_kept_) slabs_[node] = build_slabs_[record];
    pieces_[node] = build_pieces_[record];
    build_leaf_nodes_[record] = node;
    return;
  }
  // Principal component of the leaf centres: power iteration on their covariance, started from
  // the longest side of the leaf spheres' box (deterministic: fixed start, fixed iteration count).
  // One pass gathers the centres' moments (about the first centre, so that the covariance's
  // subtraction cancels little) and that box, which also centres the direct cover. (The centres'
  // own box as well would take more registers than the processor has, and cost a pass.)
  const Vec3 origin = first->sphere.center;
  Vec3 sum{0.0};
  Vec3 cover_lo{INFINITY};
  Vec3 cover_hi{-INFINITY};
  double cxx = 0, cxy = 0, cxz = 0, cyy = 0, cyz = 0, czz = 0;
  for (const BuildLeaf* n = first; n != last; ++n) {
    const Vec3& c = n->sphere.center;
    cover_lo = glm::min(cover_lo, c - n->sphere.radius);
    cover_hi = glm::max(cover_hi, c + n->sphere.radius);
    const Vec3 d = c - origin;
    sum += d;
    cxx += d.x * d.x, cxy += d.x * d.y, cxz += d.x * d.z;
    cyy += d.y * d.y, cyz += d.y * d.z, czz += d.z * d.z;
  }
  const Vec3 mean = sum / static_cast<double>(count);
  cxx -= sum.x * mean.x, cxy -= sum.x * mean.y, cxz -= sum.x * mean.z;
  cyy -= sum.y * mean.y, cyz -= sum.y * mean.z, czz -= sum.z * mean.z;
  const Vec3 extent = cover_hi - cover_lo;
  Vec3 axis = extent.x >= extent.y && extent.x >= extent.z ? Vec3{1, 0, 0}
              : extent.y >= extent.z                       ? Vec3{0, 1, 0}
                                                           : Vec3{0, 0, 1};
  // Normalised every fourth product only: the square root and division each round cost more than
  // the product (a rebuild's largest part), and four products of a covariance in square metres
  // neither overflow nor underflow a double.
  for (int round = 0; round < 3; ++round) {
    Vec3 next = axis;
    for (int i = 0; i < 4; ++i) {
      next = Vec3{cxx * next.x + cxy * next.y + cxz * next.z, cxy * next.x + cyy * next.y + cyz * next.z,
                  cxz * next.x + cyz * next.y + czz * next.z};
    }
    const double norm = length(next);
    if (!(norm > 0.0) || !std::isfinite(norm)) break;
    axis = next / norm;
  }
  // Split at the middle of the leaf set's extent along that axis. The same pass measures the direct
  // cover (cover_leaves), which needs no child yet.
  const Vec3 cover_center = 0.5 * (cover_lo + cover_hi);
  double cover_radius = 0.0;
  double pmin = INFINITY;
  double pmax = -INFINITY;
  for (const BuildLeaf* n = first; n != last; ++n) {
    const double p = dot(n->sphere.center, axis);
    pmin = std::min(pmin, p);
    pmax = std::max(pmax, p);
    cover_radius = std::max(cover_radius, length(n->sphere.center - cover_center) + n->sphere.radius);
  }
  const double middle = 0.5 * (pmin + pmax);
  BuildLeaf* split = std::partition(first, last, [&](const BuildLeaf& n) { return dot(n.sphere.center, axis) < middle; });
  if (split == first || split == last) {
    // Everything on one side (coincident centres): the median by projection, ties by creation order.
    split = first + count / 2;
    std::nth_element(first, split, last, [&](const BuildLeaf& a, const BuildLeaf& b) {
      const double pa = dot(a.sphere.center, axis);
      const double pb = dot(b.sphere.center, axis);
      return pa < pb || (pa == pb && a.record < b.record);
    });
  }
  // The direct cover waits in the node's sphere for finish_node(), which runs once both subtrees are
  // built (the last of the three tasks out: the left subtree goes first, then the right).
  spheres_[node] = inflated_sphere(cover_center, cover_radius);
  const auto split_at = static_cast<std::int32_t>(split - build_leaves_.data());
  build_tasks_.push_back({task.first, task.last, node, BuildTask::kFinish});
  build_tasks_.push_back({split_at, task.last, node, BuildTask::kRightChild});
  build_tasks_.push_back({task.first, split_at, node, BuildTask::kLeftChild});
}

void SphereTree::finish_node(std::int32_t node, const BuildLeaf* first, const BuildLeaf* last) {
  SphereTreeLinks& l = links_[node];
  l.height = 1 + std::max(links_[l.left].height, links_[l.right].height);
  const Sphere direct = spheres_[node];
  cover_leaves(node, direct, first, last);
}

// The paper's rule: a node's sphere covers every leaf sphere below it directly (`direct`, measured
// by start_node), which is tighter than covering the two child spheres; the smaller of the two
// covers is kept.
void SphereTree::cover_leaves(std::int32_t node, const Sphere& direct, const BuildLeaf* first, const BuildLeaf* last) {
  const Sphere merged = enclosing_sphere(spheres_[links_[node].left], spheres_[links_[node].right]);
  spheres_[node] = direct.radius < merged.radius ? direct : merged;
  if (!slabs_kept_) return;
  // The slab likewise from the leaves' triangles directly, along their area-weighted mean normal:
  // exact at the build, where merging the children's slabs (as refit does) widens it at every level.
  const auto triangle_of = [&](const BuildLeaf* n) { return build_mesh_->triangles[build_pieces_[static_cast<std::size_t>(n->record)].triangle]; };
  Vec3 normal{0.0};
  for (const BuildLeaf* n = first; n != last; ++n) {
    const Triangle& tri = triangle_of(n);
    const Vec3& a = build_mesh_->positions[tri[0]];
    normal += cross(build_mesh_->positions[tri[1]] - a, build_mesh_->positions[tri[2]] - a);
  }
  const double normal_length = length(normal);
  if (!(normal_length > 0.0) || !std::isfinite(normal_length)) {
    const SphereTreeLinks& l = links_[node];
    slabs_[node] = merge_slabs(spheres_[l.left], slabs_[l.left], spheres_[l.right], slabs_[l.right]);
    set_child_leans(node);
    return;
  }
  normal /= normal_length;
  double slab_lo = INFINITY;
  double slab_hi = -INFINITY;
  double magnitude = 0.0;
  for (const BuildLeaf* n = first; n != last; ++n) {
    for (const std::uint32_t v : triangle_of(n)) {
      const Vec3& p = build_mesh_->positions[v];
      const double along = dot(normal, p);
      slab_lo = std::min(slab_lo, along);
      slab_hi = std::max(slab_hi, along);
      magnitude = std::max(magnitude, max_abs(p));
    }
  }
  const double pad = 1e-12 * magnitude;
  slabs_[node] = {normal, slab_lo - pad, slab_hi + pad};
  set_child_leans(node);
}

// The children's leans against this node's axis, which the refit reuses: internal normals keep their
// direction between builds, so the sines are taken once, not at every refit.
void SphereTree::set_child_leans(std::int32_t node) {
  const SphereTreeLinks& l = links_[node];
  leans_[l.left] = lean_of(slabs_[node].normal, slabs_[l.left].normal);
  leans_[l.right] = lean_of(slabs_[node].normal, slabs_[l.right].normal);
}

// ---- Refit ------------------------------------------------------------------------------------

void SphereTree::refit_node(std::int32_t node) {
  const SphereTreeLinks& l = links_[node];
  spheres_[node] = enclosing_sphere(spheres_[l.left], spheres_[l.right]);
  if (slabs_kept_) {
    slabs_[node] = merge_slabs(spheres_[l.left], slabs_[l.left], spheres_[l.right], slabs_[l.right]);
    set_child_leans(node);
  }
  links_[node].height = 1 + std::max(links_[l.left].height, links_[l.right].height);
}

void SphereTree::refit_upward(std::int32_t node) {
  for (; node != kNoNode; node = links_[node].parent) refit_node(node);
}

void SphereTree::update_refit_order() {
  refit_leaves_.clear();
  refit_internal_.clear();
  order_dirty_ = false;
  // After every edit of a cut: each order is made only for the refit that uses it.
  if (!slabs_kept_) {
    update_sphere_refit_blocks();
    return;
  }
  if (root_ == kNoNode) return;
  // Leaves in node order; internal nodes by height (a child is always lower than its parent), so
  // the merges of one height are independent of each other and overlap in the pipeline.
  std::int32_t tallest = 0;
  for (std::int32_t n = 0; n < node_capacity(); ++n) {
    const std::int32_t h = links_[n].height;
    if (h == 0) refit_leaves_.push_back(n);
    tallest = std::max(tallest, h);
  }
  stack_.assign(static_cast<std::size_t>(tallest) + 2, 0);  // counting sort on the height
  for (std::int32_t n = 0; n < node_capacity(); ++n) {
    if (links_[n].height > 0) ++stack_[static_cast<std::size_t>(links_[n].height) + 1];
  }
  for (std::size_t h = 1; h < stack_.size(); ++h) stack_[h] += stack_[h - 1];
  refit_internal_.resize(static_cast<std::size_t>(stack_.back()));
  for (std::int32_t n = 0; n < node_capacity(); ++n) {
    const std::int32_t h = links_[n].height;
    if (h > 0) refit_internal_[static_cast<std::size_t>(stack_[static_cast<std::size_t>(h)]++)] = n;
  }
  // With every child numbered after its parent (true after a build; an insertion or removal may
  // reuse a lower slot), the internal nodes backwards are also children first, and read memory in
  // order: on a large tree that beats the order by height.
  bool preorder = true;
  for (std::int32_t n = 0; n < node_capacity() && preorder; ++n) {
    if (links_[n].height > 0) preorder = links_[n].left > n && links_[n].right > n;
  }
  if (preorder) {
    refit_internal_.clear();
    for (std::int32_t n = node_capacity() - 1; n >= 0; --n) {
      if (links_[n].height > 0) refit_internal_.push_back(n);
    }
  }
}

// The spheres-only refit's order. Its merges go four at a time, so they come in groups of one
// height, whose nodes are never one another's children. A tree far larger than the cache would be
// swept once per height that way, so the small subtrees go first, each whole while its spheres are
// in cache (its leaves, then its heights in turn), and the nodes above them last, a height at a time.
void SphereTree::update_sphere_refit_blocks() {
  // A block of height 12 holds up to 4096 leaves, 256 KiB of spheres: within any core's L2 cache,
  // and long groups (blocks of height 8 refitted the 138k gland 5-13% slower). A tree small enough
  // to stay in cache is one block: the many small blocks an uneven tree leaves would run mostly in
  // padded lanes (the 1,488-triangle gland refits 20% faster whole).
  const std::int32_t block_height = live_nodes_ <= kRefitWholeTreeNodes ? std::numeric_limits<std::int32_t>::max() : 12;
  refit_blocks_.clear();
  whole_leaves_.clear();
  sliced_leaves_.clear();
  merge_order_.clear();
  merge_group_ends_.clear();
  block_top_.clear();
  merge_children_.clear();
  corners_stale_ = true;
  if (root_ == kNoNode) return;
  const auto add_by_height = [this](std::span<const std::int32_t> nodes, std::int32_t tallest) {
    append_by_height(nodes, tallest, merge_order_);
    const std::vector<std::size_t>& next = height_slots_;
    for (std::size_t h = 1; h < next.size() - 1; ++h) {  // next[h] now ends height h
      if (next[h] != (merge_group_ends_.empty() ? 0 : merge_group_ends_.back())) merge_group_ends_.push_back(next[h]);
    }
  };
  const auto end_block = [this] { refit_blocks_.push_back({whole_leaves_.size(), sliced_leaves_.size(), merge_group_ends_.size()}); };
  // Depth first from the root, left before right: the order a build numbers the nodes in.
  std::vector<std::int32_t>& pending = stack_;
  pending.assign(1, root_);
  while (!pending.empty()) {
    const std::int32_t n = pending.back();
    pending.pop_back();
    if (links_[n].height > block_height) {
      block_top_.push_back(n);
      pending.push_back(links_[n].right);
      pending.push_back(links_[n].left);
      continue;
    }
    block_nodes_.clear();
    block_walk_.assign(1, n);
    while (!block_walk_.empty()) {
      const std::int32_t m = block_walk_.back();
      block_walk_.pop_back();
      if (links_[m].height == 0) {
        (pieces_[m].slices == 1 ? whole_leaves_ : sliced_leaves_).push_back(m);
        continue;
      }
      block_nodes_.push_back(m);
      block_walk_.push_back(links_[m].right);
      block_walk_.push_back(links_[m].left);
    }
    add_by_height(block_nodes_, links_[n].height);
    end_block();
  }
  if (!block_top_.empty()) {
    add_by_height(block_top_, links_[root_].height);
    end_block();
  }
  merge_children_.resize(merge_order_.size());
  preorder_ = true;
  for (std::int32_t n = 0; n < node_capacity() && preorder_; ++n) {
    if (links_[n].height > 0) preorder_ = links_[n].left > n && links_[n].right > n;
  }
  for (std::size_t i = 0; i < merge_order_.size(); ++i) merge_children_[i] = {links_[merge_order_[i]].left, links_[merge_order_[i]].right};
}

void SphereTree::append_by_height(std::span<const std::int32_t> nodes, std::int32_t tallest, std::vector<std::int32_t>& out) {
  std::vector<std::size_t>& next = height_slots_;
  next.assign(static_cast<std::size_t>(tallest) + 2, 0);
  for (const std::int32_t n : nodes) ++next[static_cast<std::size_t>(links_[n].height) + 1];
  next[0] = out.size();
  for (std::size_t h = 1; h < next.size(); ++h) next[h] += next[h - 1];
  out.resize(out.size() + nodes.size());
  for (const std::int32_t n : nodes) out[next[static_cast<std::size_t>(links_[n].height)]++] = n;
}

void SphereTree::refit_leaf(const TriangleMesh& mesh, std::int32_t leaf) {
  const LeafPiece& piece = pieces_[leaf];
  const Triangle& tri = mesh.triangles[piece.triangle];
  const Vec3& a = mesh.positions[tri[0]];
  const Vec3& b = mesh.positions[tri[1]];
  const Vec3& c = mesh.positions[tri[2]];
  const Sphere sphere = piece.slices == 1 ? centroid_sphere(a, b, c) : piece_sphere(mesh, piece);
  spheres_[leaf] = sphere;
  if (!slabs_kept_) return;
  // The triangle's plane (triangle_slab, with the pad taken from the sphere: every corner is within
  // |centre| + radius of the origin).
  const Vec3 n = cross(b - a, c - a);
  const double n_length = length(n);
  if (!(n_length > 0.0) || !std::isfinite(n_length)) {
    slabs_[leaf] = triangle_slab(mesh, piece.triangle, sphere);
    return;
  }
  const Vec3 normal = n * (1.0 / n_length);
  const double da = dot(normal, a);
  const double db = dot(normal, b);
  const double dc = dot(normal, c);
  const double pad = 1e-12 * (std::abs(sphere.center.x) + std::abs(sphere.center.y) + std::abs(sphere.center.z) + sphere.radius);
  slabs_[leaf] = {normal, std::min({da, db, dc}) - pad, std::max({da, db, dc}) + pad};
}

// An internal node after its children: the sphere holding theirs, and the slab along the node's own
// (unchanged) axis holding theirs: a leaf's triangle corners projected exactly, an internal child's
// region through its stored lean.
void SphereTree::refit_internal(const TriangleMesh& mesh, std::int32_t node) {
  const SphereTreeLinks& l = links_[node];
  spheres_[node] = enclosing_sphere(spheres_[l.left], spheres_[l.right]);
  if (!slabs_kept_) return;
  const Vec3 axis = slabs_[node].normal;
  double lo = INFINITY;
  double hi = -INFINITY;
  for (const std::int32_t child : {l.left, l.right}) {
    if (links_[child].height == 0) {
      const Triangle& tri = mesh.triangles[pieces_[child].triangle];
      for (const std::uint32_t v : tri) {
        const double along = dot(axis, mesh.positions[v]);
        lo = std::min(lo, along);
        hi = std::max(hi, along);
      }
    } else {
      double child_lo, child_hi;
      project_region(spheres_[child], slabs_[child], axis, leans_[child], child_lo, child_hi);
      lo = std::min(lo, child_lo);
      hi = std::max(hi, child_hi);
    }
  }
  // Every value above is a projection of a point within |centre| + radius of the origin, off by a
  // few ulps of that; the pad is far above it.
  const Sphere& s = spheres_[node];
  const double pad = 1e-11 * (std::abs(s.center.x) + std::abs(s.center.y) + std::abs(s.center.z) + s.radius);
  slabs_[node].lo = lo - pad;
  slabs_[node].hi = hi + pad;
}

void SphereTree::refit(const TriangleMesh& mesh) {
  if (order_dirty_) update_refit_order();
  last_refit_leaves_ = leaf_count_;
  // Leaves from their triangles' corners, then one pass of O(1) merges, children before parents:
  // each internal bound holds its two children's, so every leaf below stays covered. Two loops
  // without a branch on the kind of node, each reading its arrays in order.
  if (slabs_kept_) {
    for (const std::int32_t leaf : refit_leaves_) refit_leaf(mesh, leaf);
    for (const std::int32_t node : refit_internal_) refit_internal(mesh, node);
    return;
  }
  // Spheres alone: the same bounds as refit_leaf and refit_internal give, block by block, four at a time.
  const bool leaves_changed = corners_stale_;
  if (corners_stale_) {
    // The leaves' triangles keep their corners until a removal or insertion changes the order.
    whole_corners_.resize(whole_leaves_.size());
    for (std::size_t i = 0; i < whole_leaves_.size(); ++i) whole_corners_[i] = mesh.triangles[pieces_[whole_leaves_[i]].triangle];
    sliced_operands_.resize(sliced_leaves_.size());
    for (std::size_t i = 0; i < sliced_leaves_.size(); ++i) sliced_operands_[i] = slice_operands(mesh, pieces_[sliced_leaves_[i]]);
    corners_stale_ = false;
  }
  if (refit_slack_ > 0.0 && fitted_ && !leaves_changed && fitted_positions_.size() == mesh.positions.size() && refit_moved_leaves(mesh)) return;
  refit_every_sphere(mesh);
  if (leaves_changed) {
    // Edits come in runs (a stroke cuts every collision step for a while): the slack's bookkeeping,
    // a pass over every leaf and vertex, waits for the first refit without one (it made the 138,212
    // gland's cutting steps 3-4 ms costlier at the 95th percentile when it came with every edit).
    vertex_slots_stale_ = true;
    applied_slack_ = 0.0;
    fitted_ = false;
    return;
  }
  keep_fitted_positions(mesh);
}

void SphereTree::refit_every_sphere(const TriangleMesh& mesh) {
  const std::span<const std::int32_t> whole(whole_leaves_), sliced(sliced_leaves_), merges(merge_order_);
  RefitBlock begin{0, 0, 0};
  std::size_t merged = 0;  // merge_order_'s entries done
  for (const RefitBlock& block : refit_blocks_) {
    centroid_spheres(mesh.positions.data(), whole_corners_.data() + begin.whole_end, whole.subspan(begin.whole_end, block.whole_end - begin.whole_end),
                     spheres_.data());
    sliced_piece_spheres(mesh.positions.data(), sliced_operands_.data() + begin.sliced_end, sliced.subspan(begin.sliced_end, block.sliced_end - begin.sliced_end),
                         spheres_.data());
    for (std::size_t g = begin.groups_end; g < block.groups_end; ++g) {
      merge_children(merge_children_.data() + merged, merges.subspan(merged, merge_group_ends_[g] - merged), spheres_.data());
      merged = merge_group_ends_[g];
    }
    begin = block;
  }
}

// ---- Insert and remove ------------------------------------------------------------------------

void SphereTree::insert_leaf(std::int32_t leaf) {
  order_dirty_ = true;
  if (root_ == kNoNode) {
    root_ = leaf;
    links_[leaf].parent = kNoNode;
    return;
  }
  // Descend to the lowest level: at each node, the side of the plane halfway between the children's
  // centres, across the line joining them (the node's principal direction).
  const Vec3 c = spheres_[leaf].center;
  std::int32_t node = root_;
  while (!is_leaf(node)) {
    const Sphere& a = spheres_[links_[node].left];
    const Sphere& b = spheres_[links_[node].right];
    const bool to_right = dot(c - 0.5 * (a.center + b.center), b.center - a.center) > 0.0;
    node = to_right ? links_[node].right : links_[node].left;
  }
  const std::int32_t parent = allocate_node();
  const std::int32_t grandparent = links_[node].parent;
  links_[parent] = SphereTreeLinks{grandparent, node, leaf, 1};
  links_[node].parent = parent;
  links_[leaf].parent = parent;
  if (grandparent == kNoNode) {
    root_ = parent;
  } else if (links_[grandparent].left == node) {
    links_[grandparent].left = parent;
  } else {
    links_[grandparent].right = parent;
  }
  refit_upward(parent);
}

void SphereTree::insert_triangle(const TriangleMesh& mesh, std::uint32_t t) {
  ++structure_version_;
  add_triangle_leaves(mesh, t, true);
}

void SphereTree::remove_triangle(std::uint32_t t) {
  if (t >= first_leaf_.size()) return;
  ++structure_version_;
  std::int32_t leaf = first_leaf_[t];
  first_leaf_[t] = kNoNode;
  while (leaf != kNoNode) {
    const std::int32_t next = next_leaf_[leaf];
    const std::int32_t parent = links_[leaf].parent;
    if (parent == kNoNode) {
      root_ = kNoNode;
    } else {
      // The sibling takes the parent's place under the grandparent.
      const std::int32_t sibling = links_[parent].left == leaf ? links_[parent].right : links_[parent].left;
      const std::int32_t grandparent = links_[parent].parent;
      links_[sibling].parent = grandparent;
      if (grandparent == kNoNode) {
        root_ = sibling;
      } else if (links_[grandparent].left == parent) {
        links_[grandparent].left = sibling;
      } else {
        links_[grandparent].right = sibling;
      }
      free_node(parent);
      refit_upward(grandparent);
    }
    free_node(leaf);
    --leaf_count_;
    leaf = next;
  }
  order_dirty_ = true;
}

// ---- Quality ----------------------------------------------------------------------------------

SphereTreeQuality SphereTree::quality() const {
  SphereTreeQuality q;
  q.leaves = leaf_count_;
  q.height = root_ == kNoNode ? -1 : links_[root_].height;
  q.height_bound = 2.0 * std::log2(std::max(2.0, static_cast<double>(leaf_count_))) + 4.0;
  double sum = 0.0;
  std::int32_t internal = 0;
  // Node order: the same sum on every run.
  for (std::int32_t n = 0; n < node_capacity(); ++n) {
    if (links_[n].height > 0) {
      sum += spheres_[n].radius;
      ++internal;
    }
  }
  q.mean_internal_radius = internal > 0 ? sum / internal : 0.0;
  // The refit's slack grows every sphere alike; what decays the tree is the growth beyond it.
  q.radius_growth = built_mean_internal_radius_ > 0.0 ? (q.mean_internal_radius - applied_slack_) / built_mean_internal_radius_ : 1.0;
  return q;
}

bool SphereTree::should_rebuild() const {
  const SphereTreeQuality q = quality();
  return q.height > q.height_bound || q.radius_growth > 2.0;
}

bool SphereTree::must_rebuild() const {
  const SphereTreeQuality q = quality();
  return q.height > 2.0 * q.height_bound || q.radius_growth > 4.0;
}

}  // namespace resecto
