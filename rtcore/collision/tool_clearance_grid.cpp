#include "rtcore/collision/tool_clearance_grid.h"

#include <algorithm>
#include <cmath>

#include <glm/common.hpp>

#include "rtcore/geometry/closest_point.h"

namespace resecto {
namespace {

double box_distance2(const Vec3& p, const Aabb& box) {
  const Vec3 outside = glm::max(glm::max(box.min - p, p - box.max), Vec3(0.0));
  return length_squared(outside);
}


// Cells are filled a block at a time: the triangles that can be within the band of any cell of a
// block are found once per block, and each cell tests only those.
constexpr std::size_t kBlock = 4;
constexpr double kBandCells = 8.0;

}  // namespace

void ToolClearanceGrid::build(const TriangleMesh& mesh, std::size_t max_cells) {
  *this = ToolClearanceGrid{};
  if (mesh.triangle_count() == 0) return;
  std::vector<Aabb> boxes(mesh.triangle_count());
  Aabb all{Vec3(1e300), Vec3(-1e300)};
  for (std::size_t t = 0; t < boxes.size(); ++t) {
    const Vec3& a = mesh.positions[mesh.triangles[t][0]];
    const Vec3& b = mesh.positions[mesh.triangles[t][1]];
    const Vec3& c = mesh.positions[mesh.triangles[t][2]];
    boxes[t] = triangle_box(a, b, c);
    all = {glm::min(all.min, boxes[t].min), glm::max(all.max, boxes[t].max)};
  }
  // A flat or thin tool still gets cells of a sensible size: no side counts as less than 1/64 of
  // the longest.
  const Vec3 extent = all.size();
  const double longest = std::max({extent.x, extent.y, extent.z, 1e-300});
  const Vec3 sized = glm::max(extent, Vec3(longest / 64.0));
  const double cell_m = BrickGrid::cell_side_for(sized, static_cast<double>(std::max<std::size_t>(max_cells, 64)));
  band_m_ = kBandCells * cell_m;
  cells_ = BrickGrid(all.min - Vec3(band_m_), extent + Vec3(2.0 * band_m_), cell_m);
  step_m_ = band_m_ / 255.0;
  values_.assign(cells_.storage_count(), 255);
  // A stored distance never exceeds the true one: the double's own rounding is allowed for, and
  // the steps are counted down.
  const auto steps_below = [&](double distance) {
    const double steps = std::floor(distance * (1.0 - 1e-9) / step_m_);
    return static_cast<std::uint8_t>(std::clamp(steps, 0.0, 255.0));
  };

  const double half_diagonal = 0.5 * std::sqrt(3.0) * cell_m;
  const double block_half_diagonal = static_cast<double>(kBlock) * half_diagonal;
  // Every cell centre of a block is within the block's half diagonal of its centre.
  const double reach = (band_m_ + block_half_diagonal) * (1.0 + 1e-9);
  std::vector<std::pair<double, std::uint32_t>> near;  // (distance of the box from the block's centre, triangle)
  for (std::size_t bz = 0; bz < cells_.dim(2); bz += kBlock) {
    for (std::size_t by = 0; by < cells_.dim(1); by += kBlock) {
      for (std::size_t bx = 0; bx < cells_.dim(0); bx += kBlock) {
        const Vec3 block_centre = cells_.lower() + Vec3(static_cast<double>(bx), static_cast<double>(by), static_cast<double>(bz)) * cell_m +
                                  Vec3(0.5 * static_cast<double>(kBlock) * cell_m);
        near.clear();
        for (std::uint32_t t = 0; t < boxes.size(); ++t) {
          const double d2 = box_distance2(block_centre, boxes[t]);
          if (d2 <= reach * reach) near.emplace_back(std::sqrt(d2), t);
        }
        if (near.empty()) continue;
        // Nearest boxes first: a cell stops at the first box that, even moved by the cell's offset
        // from the block's centre, is farther than the nearest triangle found.
        std::sort(near.begin(), near.end());
        for (std::size_t z = bz; z < std::min(bz + kBlock, cells_.dim(2)); ++z) {
          for (std::size_t y = by; y < std::min(by + kBlock, cells_.dim(1)); ++y) {
            for (std::size_t x = bx; x < std::min(bx + kBlock, cells_.dim(0)); ++x) {
              const Vec3 centre = cells_.centre(x, y, z);
              const double offset = length(centre - block_centre) * (1.0 + 1e-9) + 1e-12 * reach;
              double best2 = band_m_ * band_m_;
              for (const auto& [box_distance, t] : near) {
                const double lower_bound = box_distance - offset;
                if (lower_bound > 0.0 && lower_bound * lower_bound >= best2) break;
                if (box_distance2(centre, boxes[t]) >= best2) continue;
                const Triangle& tri = mesh.triangles[t];
                const Vec3 q = closest_point_on_triangle(centre, mesh.positions[tri[0]], mesh.positions[tri[1]], mesh.positions[tri[2]]);
                best2 = std::min(best2, length_squared(centre - q));
              }
              values_[cells_.storage_index(x, y, z)] = steps_below(std::sqrt(best2));
            }
          }
        }
      }
    }
  }
}

}  // namespace resecto
