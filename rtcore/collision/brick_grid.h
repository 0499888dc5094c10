// BrickGrid: the cells of a uniform grid over a box, numbered brick by brick (4 x 4 x 4) so that
// neighbouring cells share cache lines. The tool's clearance grid and its proximity lists both
// store their cells in this order; a query walking the tissue looks up neighbouring cells in turn.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <limits>

#include "rtcore/geometry/vec3.h"

namespace resecto {

class BrickGrid {
 public:
  static constexpr std::size_t kBrick = 4;
  static constexpr double kMaxCellsPerAxis = 1 << 16;

  BrickGrid() = default;
  /// Cells of side `cell_m` from `lower`, enough to cover `extent` (one more than it needs on each
  /// axis, so the box's upper faces are inside).
  /// Never more than kMaxCellsPerAxis + 1 a side: a box or cell that is not finite (NaN, infinity),
  /// or a cell with no size, gets a single cell rather than an unbounded count.
  BrickGrid(const Vec3& lower, const Vec3& extent, double cell_m) : lower_(lower), cell_m_(cell_m), inverse_cell_(1.0 / cell_m) {
    const bool sized = cell_m > 0.0 && std::isfinite(inverse_cell_);
    for (std::size_t a = 0; a < 3; ++a) {
      const double span = sized ? extent[static_cast<int>(a)] * inverse_cell_ : 0.0;
      dims_[a] = (span >= 0.0 ? static_cast<std::size_t>(std::min(span, kMaxCellsPerAxis)) : 0) + 1;
      bricks_[a] = (dims_[a] + kBrick - 1) / kBrick;
    }
  }

  /// The side of cubic cells of which about `cells` fill a box of `extent`. The volume overflows
  /// to infinity past 1e102 on a side and underflows to zero (or loses its digits) below 1e-102, so
  /// then the sides' cube roots are taken apart (the normal form is kept as it was: the tool grids'
  /// values, and so the golden hashes, depend on it). A zero side came out as a zero cell, and a grid
  /// of zero cells as 65,537 cells a side: a tool 1e-110 mm across asked for terabytes.
  static double cell_side_for(const Vec3& extent, double cells) {
    const double volume = extent.x * extent.y * extent.z;
    if (std::isfinite(volume) && volume >= std::numeric_limits<double>::min()) return std::cbrt(volume / cells);
    return std::cbrt(extent.x) * std::cbrt(extent.y) * std::cbrt(extent.z) / std::cbrt(cells);
  }

  /// The storage index of the cell holding p; false when p is outside the grid.
  bool locate(const Vec3& p, std::size_t& index) const {
    std::size_t x, y, z;
    if (!cell_of(p, x, y, z)) return false;
    index = storage_index(x, y, z);
    return true;
  }
  /// The cell holding p, by its coordinates; false when p is outside the grid.
  bool cell_of(const Vec3& p, std::size_t& x, std::size_t& y, std::size_t& z) const {
    const Vec3 at = (p - lower_) * inverse_cell_;
    if (!(at.x >= 0.0 && at.y >= 0.0 && at.z >= 0.0)) return false;
    x = static_cast<std::size_t>(at.x);
    y = static_cast<std::size_t>(at.y);
    z = static_cast<std::size_t>(at.z);
    return x < dims_[0] && y < dims_[1] && z < dims_[2];
  }
  std::size_t storage_index(std::size_t x, std::size_t y, std::size_t z) const {
    const std::size_t brick = ((z / kBrick) * bricks_[1] + y / kBrick) * bricks_[0] + x / kBrick;
    return brick * kBrick * kBrick * kBrick + ((z % kBrick) * kBrick + y % kBrick) * kBrick + x % kBrick;
  }
  Vec3 centre(std::size_t x, std::size_t y, std::size_t z) const {
    return lower_ + (Vec3(static_cast<double>(x), static_cast<double>(y), static_cast<double>(z)) + 0.5) * cell_m_;
  }

  /// Storage slots: whole bricks, so a little more than the cells.
  std::size_t storage_count() const { return bricks_[0] * bricks_[1] * bricks_[2] * kBrick * kBrick * kBrick; }
  std::size_t cell_count() const { return dims_[0] * dims_[1] * dims_[2]; }
  std::size_t dim(std::size_t axis) const { return dims_[axis]; }
  const Vec3& lower() const { return lower_; }
  /// The grid's far corner (the covered box's upper corner or a little past it).
  Vec3 upper() const { return lower_ + Vec3(static_cast<double>(dims_[0]), static_cast<double>(dims_[1]), static_cast<double>(dims_[2])) * cell_m_; }
  double cell_m() const { return cell_m_; }
  double inverse_cell() const { return inverse_cell_; }

 private:
  Vec3 lower_{0.0};
  double cell_m_ = 0.0, inverse_cell_ = 0.0;
  std::array<std::size_t, 3> dims_{0, 0, 0};
  std::array<std::size_t, 3> bricks_{0, 0, 0};
};

}  // namespace resecto
