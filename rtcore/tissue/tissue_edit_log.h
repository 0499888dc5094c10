// The topology edits made to one tissue, in order, so that a second copy of the tissue can make
// exactly the same ones (MassSpringTissue::replay).
//
// Why two copies: resection's edits cost milliseconds when the loop cuts a fresh stroke, far more than
// the spare time of a 960 Hz physics tick. The core therefore keeps two copies of the tissue: the
// physics steps the front one while the collision thread edits the other and searches it; at the
// next collision tick the edited copy takes over the front's motion and becomes the front
// (Simulation), and in its next job the collision thread replays this log on the copy left behind.
// Every edit is a deterministic function of the topology, rest positions and parameters, so the
// replayed copy ends with the same slots, springs, surface faces and topology hash.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "rtcore/tissue/tet_mesh.h"

namespace resecto {

class TissueEditLog {
 public:
  enum class Kind : std::uint8_t { kMidpointNodes, kEditTetrahedra, kCompactSprings };
  /// One edit: its kind and where its arguments sit in the payload arrays.
  struct Entry {
    Kind kind = Kind::kCompactSprings;
    std::uint32_t first_parent = 0, parent_count = 0;  // kMidpointNodes
    std::uint32_t first_removed = 0, removed_count = 0;  // kEditTetrahedra
    std::uint32_t first_added = 0, added_count = 0;      // kEditTetrahedra (tetrahedra and regions)
  };

  /// Room for a collision step's edits, so recording one allocates nothing in the usual case (a
  /// larger burst grows the arrays on the collision thread, which is allowed to allocate).
  void reserve(std::size_t entries, std::size_t nodes, std::size_t tetrahedra);

  void record_midpoint_nodes(std::span<const std::array<std::uint32_t, 2>> parents);
  void record_edit(std::span<const std::uint32_t> removed, std::span<const Tetrahedron> added, std::span<const TissueRegion> regions);
  void record_compaction();
  /// A node the edits left with no tetrahedron (its velocity is zeroed where the edits are adopted).
  void record_orphan(std::uint32_t node) { orphans_.push_back(node); }

  bool empty() const { return entries_.empty(); }
  void clear();

  std::span<const Entry> entries() const { return entries_; }
  /// Every new node's parents, in the order the nodes were appended.
  std::span<const std::array<std::uint32_t, 2>> midpoint_parents() const { return parents_; }
  std::span<const std::uint32_t> orphans() const { return orphans_; }
  std::span<const std::array<std::uint32_t, 2>> parents(const Entry& e) const {
    return std::span<const std::array<std::uint32_t, 2>>(parents_).subspan(e.first_parent, e.parent_count);
  }
  std::span<const std::uint32_t> removed(const Entry& e) const { return std::span<const std::uint32_t>(removed_).subspan(e.first_removed, e.removed_count); }
  std::span<const Tetrahedron> added(const Entry& e) const { return std::span<const Tetrahedron>(added_).subspan(e.first_added, e.added_count); }
  std::span<const TissueRegion> regions(const Entry& e) const { return std::span<const TissueRegion>(regions_).subspan(e.first_added, e.added_count); }

 private:
  std::vector<Entry> entries_;
  std::vector<std::array<std::uint32_t, 2>> parents_;
  std::vector<std::uint32_t> removed_;
  std::vector<Tetrahedron> added_;
  std::vector<TissueRegion> regions_;
  std::vector<std::uint32_t> orphans_;
};

}  // namespace resecto
