// A lower bound on how far any point is from a rigid tool's surface, answered in O(1). The tool
// never deforms, so the distance from each cell centre of a uniform grid in the tool's own frame to
// its nearest triangle is worked out once, up to a band; a query subtracts the point's offset from
// its cell's centre (the distance is 1-Lipschitz). It is what lets the collision query descend the
// tissue's sphere tree alone, pruning every sphere that cannot reach the tool, instead of pairing
// each tissue sphere with the tool's spheres.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

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
    std::size_t index;
    Vec3 centre;
    if (locate(p, index, centre)) return stored(index) - length(p - centre) - radius;
    // Outside the grid, which covers the tool's box grown by the band: at least the band away,
    // plus the distance to the grid.
    const Vec3 nearest = glm::clamp(p, lower_, upper_);
    return band_m_ + length(p - nearest) - radius;
  }

  /// ball_clearance(p, radius) <= 0, without its square roots when the cell decides.
  bool ball_may_touch(const Vec3& p, double radius) const {
    std::size_t index;
    Vec3 centre;
    if (!locate(p, index, centre)) return ball_clearance(p, radius) <= 0.0;
    const double room = stored(index) - radius;
    return room <= 0.0 || length_squared(p - centre) >= room * room;
  }

  double cell_m() const { return cell_m_; }
  double band_m() const { return band_m_; }
  std::size_t cell_count() const { return dims_[0] * dims_[1] * dims_[2]; }
  const Vec3& lower() const { return lower_; }
  const Vec3& upper() const { return upper_; }

 private:
  // Cells are stored in bricks of 4 x 4 x 4, one byte each: a brick is one cache line, so the
  // lookups of a descent, which move between neighbouring cells, mostly hit lines already loaded.
  static constexpr std::size_t kBrick = 4;

  bool locate(const Vec3& p, std::size_t& index, Vec3& centre) const {
    const Vec3 at = (p - lower_) * inverse_cell_;
    if (!(at.x >= 0.0 && at.y >= 0.0 && at.z >= 0.0)) return false;
    const auto ix = static_cast<std::size_t>(at.x), iy = static_cast<std::size_t>(at.y), iz = static_cast<std::size_t>(at.z);
    if (ix >= dims_[0] || iy >= dims_[1] || iz >= dims_[2]) return false;
    index = storage_index(ix, iy, iz);
    centre = lower_ + (Vec3(static_cast<double>(ix), static_cast<double>(iy), static_cast<double>(iz)) + 0.5) * cell_m_;
    return true;
  }
  std::size_t storage_index(std::size_t x, std::size_t y, std::size_t z) const {
    const std::size_t brick = ((z / kBrick) * bricks_[1] + y / kBrick) * bricks_[0] + x / kBrick;
    return brick * kBrick * kBrick * kBrick + ((z % kBrick) * kBrick + y % kBrick) * kBrick + x % kBrick;
  }
  // A stored byte k means the centre is at least k steps from the surface (255: the band or more).
  double stored(std::size_t index) const { return static_cast<double>(values_[index]) * step_m_; }

  Vec3 lower_{0.0}, upper_{0.0};
  double cell_m_ = 0.0, inverse_cell_ = 0.0, band_m_ = 0.0, step_m_ = 0.0;
  std::array<std::size_t, 3> dims_{0, 0, 0};
  std::array<std::size_t, 3> bricks_{0, 0, 0};
  std::vector<std::uint8_t> values_;
};

}  // namespace resecto
