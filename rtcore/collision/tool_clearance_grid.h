// A lower bound on how far any point is from a rigid tool's surface, answered in O(1). The tool
// never deforms, so the distance from each cell centre of a uniform grid in the tool's own frame to
// its nearest triangle is worked out once, up to a band; a query subtracts the point's offset from
// its cell's centre (the distance is 1-Lipschitz). It is what lets the collision query descend the
// tissue's sphere tree alone, pruning every sphere that cannot reach the tool, instead of pairing
// each tissue sphere with the tool's spheres.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "rtcore/collision/brick_grid.h"
#include "rtcore/geometry/vec3.h"
#include "rtcore/mesh/triangle_mesh.h"

namespace resecto {

class ToolClearanceGrid {
 public:
  /// Builds over `mesh` (the tool's frame) with about `max_cells` cells over its bounding box; the
  /// band (how far distances are told apart) is eight cells. An empty mesh gives an empty grid.
  void build(const TriangleMesh& mesh, std::size_t max_cells = std::size_t{1} << 20);

  bool empty() const { return values_.empty(); }

  /// A lower bound on the distance from the ball (p, radius) to the tool's surface: > 0 proves the
  /// ball misses every tool triangle by at least that much. Never more than the true gap; at most
  /// about the band (farther balls read as the band plus their distance to the grid).
  double ball_clearance(const Vec3& p, double radius) const {
    std::size_t x, y, z;
    if (cells_.cell_of(p, x, y, z)) return stored(x, y, z) - length(p - cells_.centre(x, y, z)) - radius;
    // Outside the grid, which covers the tool's box grown by the band: at least the band away,
    // plus the distance to the grid.
    const Vec3 nearest = glm::clamp(p, cells_.lower(), cells_.upper());
    return band_m_ + length(p - nearest) - radius;
  }

  /// ball_clearance(p, radius) <= 0, without its square roots when the cell decides.
  bool ball_may_touch(const Vec3& p, double radius) const {
    std::size_t x, y, z;
    if (!cells_.cell_of(p, x, y, z)) return ball_clearance(p, radius) <= 0.0;
    const double room = stored(x, y, z) - radius;
    return room <= 0.0 || length_squared(p - cells_.centre(x, y, z)) >= room * room;
  }

  double cell_m() const { return cells_.cell_m(); }
  double band_m() const { return band_m_; }
  std::size_t cell_count() const { return cells_.cell_count(); }
  const Vec3& lower() const { return cells_.lower(); }
  Vec3 upper() const { return cells_.upper(); }

 private:
  // A stored byte k means the centre is at least k steps from the surface (255: the band or more).
  double stored(std::size_t x, std::size_t y, std::size_t z) const {
    return static_cast<double>(values_[cells_.storage_index(x, y, z)]) * step_m_;
  }

  // One byte a cell, in brick order: a brick of 4 x 4 x 4 is one cache line, so the lookups of a
  // descent, which move between neighbouring cells, mostly hit lines already loaded.
  BrickGrid cells_;
  double band_m_ = 0.0, step_m_ = 0.0;
  std::vector<std::uint8_t> values_;
};

}  // namespace resecto
