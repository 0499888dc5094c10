// TetRefiner: local conforming 1:8 refinement of a live tetrahedral mesh, planned as an edit the caller
// applies. Marked tetrahedra split regularly (Bey's red refinement, octahedron cut along its shortest
// diagonal); neighbours that share a split edge close with green patterns (1:2, 1:3, 1:4 of one face),
// or go red themselves when their pattern has no green closure or its children would be too flat.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "rtcore/tissue/tet_mesh.h"  // Tetrahedron, TissueRegion, Vec3

namespace resecto {

/// A live tetrahedral mesh as the refiner reads it: slots may be dead (resected).
struct TetMeshView {
  std::span<const Vec3> rest_positions;     ///< by node id, metres
  std::span<const Tetrahedron> tetrahedra;  ///< by slot; positively oriented at rest
  std::span<const std::uint8_t> alive;      ///< per slot: 1 live, 0 dead (ignored)
  std::span<const TissueRegion> regions;    ///< per slot
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
};

class TetRefiner {
 public:
  /// Reserves scratch for meshes up to these sizes so plan() does not allocate in steady use.
  TetRefiner(std::size_t max_nodes, std::size_t max_tetrahedra);
  /// Plans: every marked live slot split regularly 1:8 (the shortest interior diagonal); every live
  /// tetrahedron that shares a split edge closed conformingly, so no hanging node exists. The edit's
  /// result has exactly the volume of the removed tetrahedra (to rounding) and is deterministic
  /// (same view and marks -> same edit, byte for byte). `marked` may be unsorted/duplicated.
  const RefinementEdit& plan(const TetMeshView& mesh, std::span<const std::uint32_t> marked);

 private:
  RefinementEdit edit_;
  std::vector<std::uint8_t> slot_state_;      // per slot: 0 untouched, 1 red, 2 closure
  std::vector<std::uint8_t> node_on_split_;   // per node: 1 if a split edge ends here
  std::vector<std::uint32_t> red_slots_;      // red slots in the order they turned red
  std::vector<std::uint32_t> closure_slots_;  // slots closed by a green pattern
  std::vector<std::uint64_t> split_edges_;    // split edge keys (smaller << 32 | larger), ascending
  std::vector<std::uint64_t> new_edges_;      // edges of the slots that turned red this round
};

}  // namespace resecto
