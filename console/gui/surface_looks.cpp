// What each face of the tissue's surface is, for its colour (see surface_looks.h).
#include "console/gui/surface_looks.h"

#include <algorithm>
#include <cmath>
#include <span>

namespace resecto::gui {
namespace {

/// A face's nodes in ascending order: the same face whatever its winding or place in the list.
FaceKey face_key(const Triangle& t) {
  FaceKey k{t[0], t[1], t[2]};
  std::sort(k.begin(), k.end());
  return k;
}

/// The entry of `key` in `looks` (sorted by key), or null.
const FaceLook* find_face(const std::vector<FaceLook>& looks, const FaceKey& key) {
  const auto it = std::lower_bound(looks.begin(), looks.end(), key, [](const FaceLook& l, const FaceKey& k) { return l.key < k; });
  return it != looks.end() && it->key == key ? &*it : nullptr;
}

}  // namespace

bool original_look(SurfaceLook look) { return look == SurfaceLook::kMucosa || look == SurfaceLook::kCapsuleOut; }

void SurfaceLooks::find_parents(const SimulationSnapshot& s, const std::vector<std::uint32_t>& appeared) {
  const std::size_t nodes = s.node_count;
  node_parents_.resize(nodes, kNoParents);
  parents_checked_.resize(nodes, 0);
  // The new nodes on faces that just appeared, each looked at once: refinement puts a node at the
  // middle of the edge it splits, and on the surface both ends of that edge are its neighbours.
  std::vector<std::int32_t> slot(nodes, -1);
  std::vector<std::uint32_t> pending;
  for (std::uint32_t f : appeared)
    for (std::uint32_t n : s.surface_triangles[f])
      if (n >= initial_nodes_ && !parents_checked_[n] && slot[n] < 0) {
        slot[n] = static_cast<std::int32_t>(pending.size());
        pending.push_back(n);
      }
  if (pending.empty()) return;
  std::vector<std::vector<std::uint32_t>> neighbours(pending.size());
  for (std::uint32_t f = 0; f < s.surface_triangle_count; ++f) {
    const Triangle& t = s.surface_triangles[f];
    for (int k = 0; k < 3; ++k) {
      if (slot[t[k]] < 0) continue;
      std::vector<std::uint32_t>& list = neighbours[static_cast<std::size_t>(slot[t[k]])];
      for (int j = 1; j < 3; ++j) {
        const std::uint32_t other = t[(k + j) % 3];
        if (std::find(list.begin(), list.end(), other) == list.end()) list.push_back(other);
      }
    }
  }
  for (std::size_t i = 0; i < pending.size(); ++i) {
    const std::uint32_t n = pending[i];
    const std::vector<std::uint32_t>& list = neighbours[i];
    double best = 0.2;  // the midpoint within a fifth of the edge's length: deformation bends, not this
    for (std::size_t x = 0; x < list.size(); ++x) {
      for (std::size_t y = x + 1; y < list.size(); ++y) {
        const Vec3& a = s.node_positions[list[x]];
        const Vec3& b = s.node_positions[list[y]];
        const double length = glm::length(b - a);
        if (length <= 0.0) continue;
        const double residual = glm::length(s.node_positions[n] - 0.5 * (a + b)) / length;
        if (residual < best) {
          best = residual;
          node_parents_[n] = {std::min(list[x], list[y]), std::max(list[x], list[y])};
        }
      }
    }
    parents_checked_[n] = 1;
  }
}

bool SurfaceLooks::on_face(std::uint32_t node, const FaceKey& face, int depth) const {
  if (node == face[0] || node == face[1] || node == face[2]) return true;
  if (depth == 0 || node < initial_nodes_ || node >= node_parents_.size() || node_parents_[node] == kNoParents) return false;
  return on_face(node_parents_[node][0], face, depth - 1) && on_face(node_parents_[node][1], face, depth - 1);
}

bool SurfaceLooks::piece_of(const Triangle& t, const FaceKey& parent) const {
  // Refinement quarters a face (pieces with at most one of its corners and the middles of its
  // edges) or halves it (two corners and the middle of the edge between the others), and splits
  // pieces again: every node of a piece is a corner of the parent or made from two nodes on it. A
  // face a cut exposed behind a removed surface face has the removed tetrahedron's apex, which is
  // neither, however flat the tetrahedron.
  constexpr int kDepth = 6;  // splits of splits followed back this far
  const int shared = static_cast<int>(on_face(t[0], parent, 0)) + static_cast<int>(on_face(t[1], parent, 0)) +
                     static_cast<int>(on_face(t[2], parent, 0));
  if (shared == 3) return false;  // the parent itself, or its corners rewired: not a split
  return on_face(t[0], parent, kDepth) && on_face(t[1], parent, kDepth) && on_face(t[2], parent, kDepth);
}

void SurfaceLooks::classify(const SimulationSnapshot& s, double lining_radius_m) {
  const std::size_t nodes = s.node_count;
  const bool first = face_looks_.empty();
  // Each face keeps the look it had while it stays on the surface. The first surface seen is the
  // uncut gland: the lining near the axis, the capsule's outside elsewhere; a face of it that comes
  // back (a replay scrubbed back before the cut) takes its first look again. A face that appears later
  // is a piece of a face that disappeared when refinement split it (it keeps that face's look), or
  // a face the loop exposed: cut tissue, adenoma or capsule by the region of the tetrahedron behind
  // it. (A new node's split edge is found from the first snapshot that shows it on the surface;
  // sessions that drew different snapshots can differ by the odd face.)
  std::vector<std::uint8_t> kept(face_looks_.size(), 0);
  std::vector<std::uint32_t> appeared;
  looks_.resize(s.surface_triangle_count);
  for (std::uint32_t f = 0; f < s.surface_triangle_count; ++f) {
    const Triangle& t = s.surface_triangles[f];
    if (first) {
      const Vec3 centroid = (s.node_positions[t[0]] + s.node_positions[t[1]] + s.node_positions[t[2]]) / 3.0;
      looks_[f] = std::hypot(centroid.x, centroid.y) < lining_radius_m ? SurfaceLook::kMucosa : SurfaceLook::kCapsuleOut;
      continue;
    }
    const FaceKey key = face_key(t);
    if (const FaceLook* known = find_face(face_looks_, key)) {
      looks_[f] = known->look;
      kept[static_cast<std::size_t>(known - face_looks_.data())] = 1;
    } else if (const FaceLook* original = find_face(initial_looks_, key)) {
      looks_[f] = original->look;  // back on the surface: a replay scrubbed to before the cut
    } else {
      appeared.push_back(f);
    }
  }
  find_parents(s, appeared);
  // The faces that disappeared, tested by brute force behind a bounding-sphere check (twice the
  // parent's radius: a piece may have been pushed about since the split): live, both lists are the
  // few faces one frame's cut and refinement touched (a replay's seek can make them long for that
  // one frame), and this runs only when the topology changed.
  const std::span<const Vec3> positions(s.node_positions.data(), nodes);
  struct Gone {
    std::size_t look;
    Vec3 centre;
    double radius2;
  };
  std::vector<Gone> gone;
  for (std::size_t i = 0; i < face_looks_.size(); ++i) {
    if (kept[i] || face_looks_[i].key[2] >= nodes) continue;
    const FaceKey& k = face_looks_[i].key;
    const Vec3 centre = (positions[k[0]] + positions[k[1]] + positions[k[2]]) / 3.0;
    double r2 = 0.0;
    for (std::uint32_t id : k) r2 = std::max(r2, glm::dot(positions[id] - centre, positions[id] - centre));
    gone.push_back({i, centre, 4.0 * r2});
  }
  for (std::uint32_t f : appeared) {
    const Triangle& t = s.surface_triangles[f];
    const bool capsule = f < s.surface_regions.size() && s.surface_regions[f] == TissueRegion::kCapsule;
    looks_[f] = capsule ? SurfaceLook::kCapsuleCut : SurfaceLook::kAdenoma;
    for (const Gone& g : gone) {
      const Vec3 d = positions[t[0]] - g.centre;
      if (glm::dot(d, d) > g.radius2) continue;
      if (piece_of(t, face_looks_[g.look].key)) {
        looks_[f] = face_looks_[g.look].look;
        break;
      }
    }
  }
  face_looks_.resize(s.surface_triangle_count);
  for (std::uint32_t f = 0; f < s.surface_triangle_count; ++f) face_looks_[f] = {face_key(s.surface_triangles[f]), looks_[f]};
  std::sort(face_looks_.begin(), face_looks_.end(), [](const FaceLook& a, const FaceLook& b) { return a.key < b.key; });
  if (first) {
    initial_looks_ = face_looks_;
    initial_nodes_ = nodes;
  }

}

}  // namespace resecto::gui
