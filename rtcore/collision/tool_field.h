// ToolField: what the collision query precomputes about a rigid tool, once, in the tool's own frame:
// a lower bound on the distance to its surface anywhere (to prune the tissue's spheres that cannot
// reach it), and which of its triangles lie near any point, at a few reaches (to find the triangles
// a tissue leaf can meet without a tree of the tool's own).
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "rtcore/collision/tool_clearance_grid.h"
#include "rtcore/collision/tool_proximity_grid.h"
#include "rtcore/mesh/triangle_mesh.h"

namespace resecto {

/// A tool triangle's plane in the tool's frame: every point x of the triangle has
/// |normal . x - offset| <= thickness (its vertices' spread off the computed plane, plus rounding).
/// Its box too, in the same frame (where a long triangle of the sheath is thin along two axes).
struct ToolPlane {
  Vec3 normal{0.0};
  double offset = 0.0;
  double thickness = 0.0;
  Aabb box;
};

class ToolField {
 public:
  static constexpr std::size_t kReaches = 5;

  /// Builds over `mesh` in its own frame. Costs tens of milliseconds for the resectoscope: a
  /// tool's, like its tree's, is built once.
  void build(const TriangleMesh& mesh);
  bool empty() const { return clearance_.empty(); }

  const ToolClearanceGrid& clearance() const { return clearance_; }

  /// Sets `triangles` to the tool's triangles that may lie within `radius` of `p` (every one that
  /// does, in ascending order, and some that do not). False, leaving it alone, when the radius is
  /// past the largest reach.
  bool near(const Vec3& p, double radius, std::span<const std::uint32_t>& triangles) const {
    const ToolProximityGrid* grid = lists_for(radius);
    if (grid == nullptr) return false;
    triangles = grid->candidates(p);
    return true;
  }
  /// Starts loading what near(p, radius) will read.
  void prefetch_near(const Vec3& p, double radius) const {
    if (const ToolProximityGrid* grid = lists_for(radius)) grid->prefetch(p);
  }
  /// Starts loading the list near(p, radius) will read, once prefetch_near() has loaded its bounds.
  void prefetch_near_list(const Vec3& p, double radius) const {
    if (const ToolProximityGrid* grid = lists_for(radius)) grid->prefetch_list(p);
  }
  /// Per tool triangle, its plane: a ball that stays off it by more than the thickness cannot meet
  /// the triangle (the cheap test ahead of the box and exact tests).
  const ToolPlane& plane(std::uint32_t triangle) const { return planes_[triangle]; }

 private:
  // The lists of the smallest reach that holds a sphere of this radius; none past the largest.
  const ToolProximityGrid* lists_for(double radius) const {
    for (std::size_t k = 0; k < kReaches; ++k) {
      if (radius <= usable_reach_[k]) return &near_[k];
    }
    return nullptr;
  }

  ToolClearanceGrid clearance_;
  std::array<ToolProximityGrid, kReaches> near_;
  std::array<double, kReaches> usable_reach_{};  // each list's reach, less a margin for rounding
  std::vector<ToolPlane> planes_;
};

}  // namespace resecto
