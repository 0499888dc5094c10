// The refit with slack: a deformable surface under a tool moves a lot where the tool presses and
// hardly at all elsewhere, yet a plain refit recomputes every sphere after every step (on the
// 138,240-triangle gland a pass over ~280,000 nodes, most of a collision step's refit). With every
// leaf sphere grown by a slack, a leaf whose corners have each stayed within the slack of where
// they were at its last fit still holds its triangle, since every point of a triangle is a weighted
// mean of its corners. So a refit checks each surface vertex against the position its leaves were
// fitted to, fits again only the leaves of the vertices that moved further, at those vertices'
// current positions and the others' fitted ones (which keeps one fitted position per vertex true for
// all its leaves), and merges their ancestors, children before parents.
#include <algorithm>
#include <bit>

#include "rtcore/collision/sphere_refit_kernel.h"
#include "rtcore/collision/sphere_tree.h"

namespace resecto {

void SphereTree::set_refit_slack(double slack) {
  refit_slack_ = slack > 0.0 ? slack : 0.0;
  fitted_ = false;  // the next refit fits every leaf with the new slack
}

void SphereTree::keep_fitted_positions(const TriangleMesh& mesh) {
  if (!(refit_slack_ > 0.0)) {
    applied_slack_ = 0.0;
    fitted_ = false;
    return;
  }
  // Growing every sphere alike keeps each parent holding its children: the sphere over two spheres
  // grown by s is the sphere over them grown by s.
  for (std::int32_t n = 0; n < node_capacity(); ++n) spheres_[static_cast<std::size_t>(n)].radius += refit_slack_;
  applied_slack_ = refit_slack_;
  fitted_positions_.assign(mesh.positions.begin(), mesh.positions.end());
  if (vertex_slots_stale_ || vertex_slot_begin_.size() != mesh.positions.size() + 1) update_vertex_slots(mesh.positions.size());
  vertex_slots_stale_ = false;
  moved_slot_bits_.assign((whole_leaves_.size() + sliced_leaves_.size() + 63) / 64, 0);
  dirty_node_bits_.assign((static_cast<std::size_t>(node_capacity()) + 63) / 64, 0);
  fitted_ = true;
}

void SphereTree::update_vertex_slots(std::size_t vertex_count) {
  // A counting sort of the slots by corner: counts, their running sums, then each slot in place.
  vertex_slot_begin_.assign(vertex_count + 1, 0);
  const auto whole_count = static_cast<std::int32_t>(whole_leaves_.size());
  const auto for_each_corner = [&](auto&& visit) {
    for (std::int32_t i = 0; i < whole_count; ++i) {
      for (const std::uint32_t v : whole_corners_[static_cast<std::size_t>(i)]) visit(v, i);
    }
    for (std::size_t i = 0; i < sliced_operands_.size(); ++i) {
      for (const std::uint32_t v : sliced_operands_[i].corners) visit(v, whole_count + static_cast<std::int32_t>(i));
    }
  };
  for_each_corner([&](std::uint32_t v, std::int32_t) { ++vertex_slot_begin_[v + 1]; });
  slack_vertices_.clear();
  for (std::size_t v = 0; v < vertex_count; ++v) {
    if (vertex_slot_begin_[v + 1] > 0) slack_vertices_.push_back(static_cast<std::int32_t>(v));
    vertex_slot_begin_[v + 1] += vertex_slot_begin_[v];
  }
  vertex_slots_.resize(static_cast<std::size_t>(vertex_slot_begin_[vertex_count]));
  // Filled by moving each vertex's start on, then moved back.
  for_each_corner([&](std::uint32_t v, std::int32_t slot) { vertex_slots_[static_cast<std::size_t>(vertex_slot_begin_[v]++)] = slot; });
  for (std::size_t v = vertex_count; v > 0; --v) vertex_slot_begin_[v] = vertex_slot_begin_[v - 1];
  vertex_slot_begin_[0] = 0;
}

bool SphereTree::refit_moved_leaves(const TriangleMesh& mesh) {
  const double slack2 = refit_slack_ * refit_slack_;
  // A moved vertex takes about two leaves of its own (a surface has twice as many triangles as
  // vertices): past an eighth of the leaves' count in moved vertices (about a quarter of the leaves),
  // the full refit's passes in memory order are the cheaper.
  const std::size_t most = (whole_leaves_.size() + sliced_leaves_.size()) / 8;
  std::size_t moved = 0;
  // Every vertex that moved first, so that each leaf below is fitted to its corners' final fitted
  // positions.
  for (const std::int32_t v : slack_vertices_) {
    const auto vi = static_cast<std::size_t>(v);
    const Vec3 d = mesh.positions[vi] - fitted_positions_[vi];
    if (dot(d, d) <= slack2) continue;  // a NaN counts as moved: its leaves are fitted, and show it
    if (++moved > most) {
      std::fill(moved_slot_bits_.begin(), moved_slot_bits_.end(), 0);
      return false;  // the full refit fits every position anew
    }
    fitted_positions_[vi] = mesh.positions[vi];
    for (std::int32_t k = vertex_slot_begin_[vi]; k < vertex_slot_begin_[vi + 1]; ++k) {
      const auto slot = static_cast<std::size_t>(vertex_slots_[static_cast<std::size_t>(k)]);
      moved_slot_bits_[slot / 64] |= std::uint64_t{1} << (slot % 64);
    }
  }
  // The leaves in slot order, which is the tree's memory order; each marks its ancestors up to the
  // first one already marked.
  last_refit_leaves_ = 0;
  for (std::size_t word = 0; word < moved_slot_bits_.size(); ++word) {
    for (std::uint64_t bits = moved_slot_bits_[word]; bits != 0; bits &= bits - 1) {
      fit_moved_leaf(64 * word + static_cast<std::size_t>(std::countr_zero(bits)));
      ++last_refit_leaves_;
    }
    moved_slot_bits_[word] = 0;
  }
  merge_dirty_nodes();
  return true;
}

void SphereTree::fit_moved_leaf(std::size_t slot) {
  const Vec3* fitted = fitted_positions_.data();
  std::int32_t leaf;
  Sphere fit;
  if (slot < whole_leaves_.size()) {
    leaf = whole_leaves_[slot];
    const Triangle& t = whole_corners_[slot];
    fit = centroid_sphere(fitted[t[0]], fitted[t[1]], fitted[t[2]]);
  } else {
    leaf = sliced_leaves_[slot - whole_leaves_.size()];
    const SliceOperands& o = sliced_operands_[slot - whole_leaves_.size()];
    fit = slice_sphere(fitted[o.corners[0]], fitted[o.corners[1]], fitted[o.corners[2]], o.t0, o.t1);
  }
  spheres_[static_cast<std::size_t>(leaf)] = inflated_sphere(fit.center, fit.radius + refit_slack_);
  for (std::int32_t n = links_[static_cast<std::size_t>(leaf)].parent; n != kNoNode; n = links_[static_cast<std::size_t>(n)].parent) {
    std::uint64_t& word = dirty_node_bits_[static_cast<std::size_t>(n) / 64];
    const std::uint64_t bit = std::uint64_t{1} << (static_cast<std::size_t>(n) % 64);
    if ((word & bit) != 0) break;  // and so are its ancestors
    word |= bit;
  }
}

void SphereTree::merge_dirty_nodes() {
  const auto merge = [this](std::int32_t n) {
    const SphereTreeLinks& l = links_[static_cast<std::size_t>(n)];
    spheres_[static_cast<std::size_t>(n)] = enclosing_sphere(spheres_[static_cast<std::size_t>(l.left)], spheres_[static_cast<std::size_t>(l.right)]);
  };
  if (preorder_) {
    // Every child numbered after its parent (a build's layout): backwards is children first.
    for (std::size_t word = dirty_node_bits_.size(); word-- > 0;) {
      for (std::uint64_t bits = dirty_node_bits_[word]; bits != 0;) {
        const int top = 63 - std::countl_zero(bits);
        merge(static_cast<std::int32_t>(64 * word + static_cast<std::size_t>(top)));
        bits &= ~(std::uint64_t{1} << top);
      }
      dirty_node_bits_[word] = 0;
    }
    return;
  }
  // Edits reuse lower slots: by height instead (a parent is taller than either child).
  dirty_nodes_.clear();
  std::int32_t tallest = 0;
  for (std::size_t word = 0; word < dirty_node_bits_.size(); ++word) {
    for (std::uint64_t bits = dirty_node_bits_[word]; bits != 0; bits &= bits - 1) {
      const auto n = static_cast<std::int32_t>(64 * word + static_cast<std::size_t>(std::countr_zero(bits)));
      dirty_nodes_.push_back(n);
      tallest = std::max(tallest, links_[static_cast<std::size_t>(n)].height);
    }
    dirty_node_bits_[word] = 0;
  }
  dirty_by_height_.clear();
  append_by_height(dirty_nodes_, tallest, dirty_by_height_);
  for (const std::int32_t n : dirty_by_height_) merge(n);
}

}  // namespace resecto
