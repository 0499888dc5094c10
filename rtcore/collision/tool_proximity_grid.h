// Which triangles of a rigid tool part lie within a fixed reach of a point, answered in O(1). A part
// never deforms, so this is worked out once, in the part's own frame, on a uniform grid: each cell
// lists every triangle that comes within the reach of any point of the cell. The contact search
// asks it for each tissue node near the part (in the part's frame) instead of descending the part's
// sphere tree per node, and a node in an empty cell, or outside the grid, is out of reach at once.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "rtcore/collision/brick_grid.h"
#include "rtcore/geometry/vec3.h"
#include "rtcore/mesh/triangle_mesh.h"

namespace resecto {

class ToolProximityGrid {
 public:
  /// Builds the grid over `mesh` (the part's frame) for points within `reach_m` of it. Cells are
  /// `reach_m / 2` on a side, or larger so the grid has at most `max_cells` cells.
  void build(const TriangleMesh& mesh, double reach_m, std::size_t max_cells = std::size_t{1} << 18);

  /// Triangles (ascending index) that may lie within the reach of `p`: every one that does, and
  /// some that do not (those near the cell but not near `p`). Empty when nothing is in reach.
  std::span<const std::uint32_t> candidates(const Vec3& p) const {
    std::size_t cell;
    if (!cells_.locate(p, cell)) return {};
    return {triangles_.data() + first_[cell], triangles_.data() + first_[cell + 1]};
  }

  /// Starts loading the list candidates(p) will read.
  void prefetch(const Vec3& p) const {
    std::size_t cell;
    if (cells_.locate(p, cell)) __builtin_prefetch(first_.data() + cell);
  }
  /// Starts loading the triangles candidates(p) will read, once prefetch(p) has loaded their bounds.
  void prefetch_list(const Vec3& p) const {
    std::size_t cell;
    if (cells_.locate(p, cell)) __builtin_prefetch(triangles_.data() + first_[cell]);
  }

  /// The box the cells cover: the mesh's bounding box grown by the reach. Nothing outside it is
  /// within the reach of the mesh.
  const Vec3& lower() const { return cells_.lower(); }
  const Vec3& upper() const { return upper_; }
  double cell_m() const { return cells_.cell_m(); }
  std::size_t cell_count() const { return cells_.cell_count(); }
  /// Triangle entries over all cells: the grid's size.
  std::size_t entry_count() const { return triangles_.size(); }

 private:
  // The lists are stored in the cells' brick order: the lookups of neighbouring points share
  // cache lines.
  BrickGrid cells_;
  Vec3 upper_{0.0};
  std::vector<std::uint32_t> first_{0};  // cell c's triangles: triangles_[first_[c], first_[c + 1])
  std::vector<std::uint32_t> triangles_;
};

}  // namespace resecto
