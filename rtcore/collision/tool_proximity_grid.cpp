#include "rtcore/collision/tool_proximity_grid.h"

#include <algorithm>
#include <cmath>

#include <glm/common.hpp>
#include <glm/geometric.hpp>

#include "rtcore/geometry/closest_point.h"

namespace resecto {

void ToolProximityGrid::build(const TriangleMesh& mesh, double reach_m, std::size_t max_cells) {
  *this = ToolProximityGrid{};
  if (mesh.triangle_count() == 0) return;
  Vec3 low(1e300), high(-1e300);
  for (const Triangle& t : mesh.triangles) {
    for (std::uint32_t v : t) {
      low = glm::min(low, mesh.positions[v]);
      high = glm::max(high, mesh.positions[v]);
    }
  }
  const Vec3 lower = low - Vec3(reach_m);
  upper_ = high + Vec3(reach_m);
  const Vec3 extent = upper_ - lower;
  // Half the reach keeps a cell's lists near the true ones (a list holds what is within the reach
  // plus half the cell's diagonal); a long part gets larger cells rather than an unbounded grid.
  cells_ = BrickGrid(lower, extent, std::max(0.5 * reach_m, BrickGrid::cell_side_for(extent, static_cast<double>(max_cells))));

  // Any point of a cell is within half its diagonal of the centre, so a triangle within the reach
  // of such a point is within reach + half diagonal of the centre: the test below keeps it.
  const double half_diagonal = 0.5 * std::sqrt(3.0) * cells_.cell_m();
  const double keep = reach_m + half_diagonal;
  std::vector<std::pair<std::uint32_t, std::uint32_t>> entries;  // (cell, triangle), triangles ascending
  const auto cell_of = [&](double coordinate, int axis) {
    const double at = std::floor((coordinate - lower[axis]) * cells_.inverse_cell());
    return static_cast<std::size_t>(std::clamp(at, 0.0, static_cast<double>(cells_.dim(static_cast<std::size_t>(axis)) - 1)));
  };
  for (std::uint32_t t = 0; t < mesh.triangle_count(); ++t) {
    const Vec3& a = mesh.positions[mesh.triangles[t][0]];
    const Vec3& b = mesh.positions[mesh.triangles[t][1]];
    const Vec3& c = mesh.positions[mesh.triangles[t][2]];
    const Aabb box = triangle_box(a, b, c);
    const Vec3 box_low = box.min - Vec3(keep), box_high = box.max + Vec3(keep);
    const std::size_t x0 = cell_of(box_low.x, 0), x1 = cell_of(box_high.x, 0);
    const std::size_t y0 = cell_of(box_low.y, 1), y1 = cell_of(box_high.y, 1);
    const std::size_t z0 = cell_of(box_low.z, 2), z1 = cell_of(box_high.z, 2);
    for (std::size_t z = z0; z <= z1; ++z) {
      for (std::size_t y = y0; y <= y1; ++y) {
        for (std::size_t x = x0; x <= x1; ++x) {
          const Vec3 centre = cells_.centre(x, y, z);
          const Vec3 q = closest_point_on_triangle(centre, a, b, c);
          if (glm::dot(centre - q, centre - q) > keep * keep) continue;
          entries.emplace_back(static_cast<std::uint32_t>(cells_.storage_index(x, y, z)), t);
        }
      }
    }
  }
  // Counting sort by cell; stable, so each cell's triangles stay ascending.
  first_.assign(cells_.storage_count() + 1, 0);
  for (const auto& [cell, t] : entries) ++first_[cell + 1];
  for (std::size_t c = 0; c < cells_.storage_count(); ++c) first_[c + 1] += first_[c];
  triangles_.resize(entries.size());
  std::vector<std::uint32_t> fill(first_.begin(), first_.end() - 1);
  for (const auto& [cell, t] : entries) triangles_[fill[cell]++] = t;
}

}  // namespace resecto
