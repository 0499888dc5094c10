// TetRefiner: local conforming 1:8 refinement of a live tetrahedral mesh, planned as an edit the caller
// applies. Marked tetrahedra split regularly (Bey's red refinement, octahedron cut along its shortest
// diagonal); neighbours that share a split edge close with green patterns (1:2, 1:3, 1:4 of one face),
// or go red themselves when their pattern has no green closure or its children would be too flat.
#pragma once

#include <array>
#include <cstdint>
#include <limits>
#include <span>
#include <vector>

#include "rtcore/tissue/tet_mesh.h"  // Tetrahedron, TissueRegion, Vec3
#include "rtcore/tissue/tet_topology.h"

namespace resecto {

/// A live tetrahedral mesh as the refiner reads it: slots may be dead (resected).
struct TetMeshView {
  std::span<const Vec3> rest_positions;     ///< by node id, metres
  std::span<const Tetrahedron> tetrahedra;  ///< by slot; positively oriented at rest
  std::span<const std::uint8_t> alive;      ///< per slot: 1 live, 0 dead (ignored)
  std::span<const TissueRegion> regions;    ///< per slot
  /// The live tetrahedra around each node, when the caller keeps them (the tissue does): the plan
  /// then reads only the lists of the split edges' nodes instead of passing over every slot.
  const TetTopology* topology = nullptr;
};

/// A conforming refinement, as an edit the caller applies (the refiner changes nothing itself).
struct RefinementEdit {
  std::uint32_t first_new_node = 0;  ///< == rest_positions.size() at planning time
  /// New node first_new_node + k is the midpoint of new_node_parents[k] (rest AND current positions
  /// and velocities are the parents' averages); parents are always older nodes, never new ones.
  std::vector<std::array<std::uint32_t, 2>> new_node_parents;
  std::vector<std::uint32_t> removed_tetrahedra;  ///< slots that disappear, ascending, all live
  std::vector<Tetrahedron> added_tetrahedra;      ///< positively oriented at rest positions
  std::vector<TissueRegion> added_regions;        ///< each child inherits its parent's region
  std::vector<std::uint32_t> added_parent;        ///< the removed slot each child came from
  std::int32_t red_tetrahedra = 0;                ///< split regularly 1:8 (marked + upgraded)
  std::int32_t closure_tetrahedra = 0;            ///< split only to close the conforming mesh
  /// The plan would split more than the limit plan() was given: it was abandoned, and the lists
  /// above are empty.
  bool exceeded = false;
};

/// Cost: proportional to the refined region when the view carries the topology (the slots around
/// each split edge's first node); otherwise one pass over the slots (two when the closure spreads
/// beyond the marked slots' neighbours, and one more for each further ring), the rest proportional
/// to the refined region. Per-node and per-slot scratch is sized at construction (and grows if a
/// mesh outgrows it); per-plan lists are sized for plans of about a thousand slots and grow once when
/// a plan is larger, then stay: after the first plans, plan() allocates nothing. The returned edit
/// lives until the next plan().
class TetRefiner {
 public:
  /// Reserves scratch for meshes up to these sizes so plan() does not allocate in steady use.
  TetRefiner(std::size_t max_nodes, std::size_t max_tetrahedra);
  /// Plans: every marked live slot split regularly 1:8 (the shortest interior diagonal); every live
  /// tetrahedron that shares a split edge closed conformingly, so no hanging node exists. The edit's
  /// result has exactly the volume of the removed tetrahedra (to rounding) and is deterministic
  /// (same view and marks -> same edit, byte for byte). `marked` may be unsorted/duplicated.
  /// `limit`: the most tetrahedra (red and closures) the caller would apply; a plan growing past it
  /// stops there and comes back `exceeded`, costing about the limit's worth of planning instead of
  /// the whole spread.
  const RefinementEdit& plan(const TetMeshView& mesh, std::span<const std::uint32_t> marked,
                             std::size_t limit = std::numeric_limits<std::size_t>::max());

 private:
  void cover(std::uint32_t node);
  /// Without the topology: lists every live slot touching a covered node (candidates_), and under
  /// each covered node the candidates holding it (incidence_), in one pass over the slots.
  void gather_candidates(const TetMeshView& mesh);
  /// Without the topology: when a red slot from `first_unsplit` on has a node outside the cover,
  /// widens the cover by every candidate's nodes (one ring) and gathers again; returns whether it did.
  bool widen_cover(const TetMeshView& mesh, std::size_t first_unsplit);
  /// Marks the red slot's edges split in every live slot holding them and queues those for judging.
  void split_around(const TetMeshView& mesh, std::uint32_t red_slot);
  /// Marks edge (a, b) split in slot s (unless red) and queues it for judging.
  void split_edge_in(const TetMeshView& mesh, std::uint32_t s, std::uint32_t a, std::uint32_t b);
  /// Leaves the per-slot and per-node scratch as the next plan expects it.
  void clear_scratch();

  RefinementEdit edit_;
  std::vector<std::uint8_t> slot_state_;          // per slot: red, queued, touched bits
  std::vector<std::uint8_t> slot_mask_;           // per slot: which of its six edges are split
  std::vector<std::uint8_t> slot_verdict_;        // per slot: the last green/red verdict and its mask
  std::vector<std::uint8_t> node_is_covered_;     // per node: 1 if covered
  std::vector<std::uint32_t> node_covered_;       // per node: its index in covered_nodes_, or ~0u
  std::vector<std::uint32_t> covered_nodes_;      // nodes whose every live slot is a candidate
  std::vector<std::uint32_t> candidates_;         // live slots touching a covered node, ascending
  std::vector<std::uint32_t> incidence_offsets_;  // per covered node: where its slots start in incidence_
  std::vector<std::uint32_t> incidence_cursor_;   // fill positions while incidence_ is built
  std::vector<std::uint32_t> incidence_;          // candidates by covered node, ascending within each
  std::vector<std::uint32_t> to_judge_;           // slots to judge this round, ascending
  std::vector<std::uint32_t> touched_;            // every slot given a split edge or turned red
  std::vector<std::uint32_t> red_slots_;          // red slots in the order they turned red
  std::vector<std::uint32_t> closure_slots_;      // slots closed by a green pattern
  std::vector<std::uint64_t> split_edges_;        // split edge keys (smaller << 32 | larger), ascending
};

}  // namespace resecto
