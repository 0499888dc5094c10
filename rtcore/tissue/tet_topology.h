// TetTopology: the live tetrahedral mesh that resection edits. Tetrahedra sit in slots (a removed
// one leaves a dead slot that a later addition reuses), each with its four face neighbours, and every
// node keeps the list of live tetrahedra around it. Capacities are fixed at construction: an edit that
// would pass them is refused by its caller (MassSpringTissue), never grown into.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "rtcore/tissue/tet_mesh.h"

namespace resecto {

/// Faces of a positively oriented tetrahedron (a, b, c, d): face f is opposite corner f, its corners
/// wound outward.
inline constexpr int kTetFaceCorners[4][3] = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};
/// The six edges as corner pairs.
inline constexpr int kTetEdgeCorners[6][2] = {{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}};

class TetTopology {
 public:
  static constexpr std::int32_t kNone = -1;

  /// Takes the mesh's tetrahedra as slots [0, count) and finds their neighbours. Room for
  /// `tetrahedron_capacity` slots and `node_capacity` nodes is reserved here.
  TetTopology(std::span<const Tetrahedron> tetrahedra, std::span<const TissueRegion> regions, std::size_t node_count,
              std::size_t tetrahedron_capacity, std::size_t node_capacity);

  std::size_t slot_count() const { return tetrahedra_.size(); }
  std::size_t live_count() const { return live_; }
  std::size_t tetrahedron_capacity() const { return tetrahedron_capacity_; }
  /// Slots a batch of additions can still take (dead slots plus unused capacity).
  std::size_t free_slots() const { return free_.size() + (tetrahedron_capacity_ - tetrahedra_.size()); }
  std::size_t node_count() const { return node_head_.size(); }
  std::size_t node_capacity() const { return node_capacity_; }

  bool alive(std::uint32_t t) const { return alive_[t] != 0; }
  const Tetrahedron& tetrahedron(std::uint32_t t) const { return tetrahedra_[t]; }
  TissueRegion region(std::uint32_t t) const { return regions_[t]; }
  std::span<const Tetrahedron> tetrahedra() const { return tetrahedra_; }
  std::span<const std::uint8_t> alive_flags() const { return alive_; }
  std::span<const TissueRegion> regions() const { return regions_; }
  /// The live tetrahedron across face f of t, or kNone where the face is on the boundary.
  std::int32_t neighbor(std::uint32_t t, int f) const { return neighbors_[4 * t + static_cast<std::uint32_t>(f)]; }
  /// Face f of t, wound outward from t.
  Triangle face(std::uint32_t t, int f) const {
    const Tetrahedron& tet = tetrahedra_[t];
    return {tet[kTetFaceCorners[f][0]], tet[kTetFaceCorners[f][1]], tet[kTetFaceCorners[f][2]]};
  }
  /// Live tetrahedra around `node`: how many, and each (most recently added first).
  std::uint32_t valence(std::uint32_t node) const { return node_valence_[node]; }
  template <typename Visit>
  void for_each_tetrahedron_of(std::uint32_t node, Visit&& visit) const {
    for (std::int32_t e = node_head_[node]; e != kNone; e = entry_next_[static_cast<std::uint32_t>(e)]) visit(static_cast<std::uint32_t>(e) / 4);
  }

  /// Appends a node with no tetrahedron yet (nodes are never removed: an orphan keeps its id).
  void add_node();
  /// Kills slot t: unlinks it from its neighbours and its nodes; the slot becomes free.
  void remove(std::uint32_t t);
  /// Adds a live tetrahedron over existing nodes, linking it to the live tetrahedra it shares a face
  /// with; reuses the most recently freed slot, else the next unused one. Returns the slot.
  std::uint32_t add(const Tetrahedron& tet, TissueRegion region);

 private:
  void link(std::uint32_t t);

  std::vector<Tetrahedron> tetrahedra_;
  std::vector<TissueRegion> regions_;
  std::vector<std::uint8_t> alive_;
  std::vector<std::int32_t> neighbors_;  // 4 per slot
  std::vector<std::uint32_t> free_;      // dead slots, reused last-in first-out
  // Node -> live tetrahedra: doubly linked lists whose entry 4 t + c stands for corner c of slot t.
  std::vector<std::int32_t> node_head_;
  std::vector<std::uint32_t> node_valence_;
  std::vector<std::int32_t> entry_next_, entry_prev_;
  std::size_t live_ = 0;
  std::size_t tetrahedron_capacity_ = 0;
  std::size_t node_capacity_ = 0;
};

}  // namespace resecto
