// Recording a tissue's topology edits for the second copy's replay.
#include "rtcore/tissue/tissue_edit_log.h"

namespace resecto {

void TissueEditLog::reserve(std::size_t entries, std::size_t nodes, std::size_t tetrahedra) {
  entries_.reserve(entries);
  parents_.reserve(nodes);
  orphans_.reserve(nodes);
  removed_.reserve(tetrahedra);
  added_.reserve(tetrahedra);
  regions_.reserve(tetrahedra);
}

void TissueEditLog::record_midpoint_nodes(std::span<const std::array<std::uint32_t, 2>> parents) {
  Entry e;
  e.kind = Kind::kMidpointNodes;
  e.first_parent = static_cast<std::uint32_t>(parents_.size());
  e.parent_count = static_cast<std::uint32_t>(parents.size());
  parents_.insert(parents_.end(), parents.begin(), parents.end());
  entries_.push_back(e);
}

void TissueEditLog::record_edit(std::span<const std::uint32_t> removed, std::span<const Tetrahedron> added,
                                std::span<const TissueRegion> regions) {
  Entry e;
  e.kind = Kind::kEditTetrahedra;
  e.first_removed = static_cast<std::uint32_t>(removed_.size());
  e.removed_count = static_cast<std::uint32_t>(removed.size());
  e.first_added = static_cast<std::uint32_t>(added_.size());
  e.added_count = static_cast<std::uint32_t>(added.size());
  removed_.insert(removed_.end(), removed.begin(), removed.end());
  added_.insert(added_.end(), added.begin(), added.end());
  regions_.insert(regions_.end(), regions.begin(), regions.end());
  entries_.push_back(e);
}

void TissueEditLog::record_compaction() {
  Entry e;
  e.kind = Kind::kCompactSprings;
  entries_.push_back(e);
}

void TissueEditLog::clear() {
  entries_.clear();
  parents_.clear();
  removed_.clear();
  added_.clear();
  regions_.clear();
  orphans_.clear();
}

}  // namespace resecto
