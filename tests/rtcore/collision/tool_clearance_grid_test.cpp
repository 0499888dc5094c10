// The clearance grid against brute force: at random points in and around the resectoscope, and for
// random radii, the bound never exceeds the true distance from the ball to the nearest triangle
// (the query's pruning rests on it), the quick test agrees with the bound, and near the surface
// the bound is within about a cell of the truth (else it would prune nothing).
#include "rtcore/collision/tool_clearance_grid.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include "rtcore/anatomy/resectoscope.h"
#include "rtcore/geometry/closest_point.h"
#include "scene.h"

namespace resecto {
namespace {

double distance_to_surface(const TriangleMesh& mesh, const Vec3& p) {
  double best = INFINITY;
  for (const Triangle& tri : mesh.triangles) {
    const Vec3 q = closest_point_on_triangle(p, mesh.positions[tri[0]], mesh.positions[tri[1]], mesh.positions[tri[2]]);
    best = std::min(best, length(p - q));
  }
  return best;
}

void expect_lower_bound(const TriangleMesh& mesh, std::size_t max_cells) {
  ToolClearanceGrid grid;
  grid.build(mesh, max_cells);
  ASSERT_FALSE(grid.empty());
  std::mt19937_64 random(3);
  const Vec3 pad(2.0 * grid.band_m());
  const Vec3 low = grid.lower() - pad, high = grid.upper() + pad;
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  int near_surface = 0;
  double worst_slack = 0.0;
  for (int i = 0; i < 20000; ++i) {
    Vec3 p = low + Vec3(unit(random), unit(random), unit(random)) * (high - low);
    if (i % 2 == 0) {
      // Half the points within a band's width of a corner: where pruning decides.
      const Vec3& corner = mesh.positions[mesh.triangles[random() % mesh.triangle_count()][1]];
      p = corner + (Vec3(unit(random), unit(random), unit(random)) - 0.5) * (2.0 * grid.band_m());
    }
    const double radius = unit(random) * grid.band_m();
    const double truth = distance_to_surface(mesh, p) - radius;
    const double bound = grid.ball_clearance(p, radius);
    ASSERT_LE(bound, truth) << "point " << i;
    ASSERT_EQ(grid.ball_may_touch(p, radius), bound <= 0.0) << "point " << i;
    if (truth + radius < 0.5 * grid.band_m()) {
      ++near_surface;
      worst_slack = std::max(worst_slack, truth - bound);
    }
  }
  EXPECT_GT(near_surface, 2000);
  // The bound loses at most the offset from the cell's centre and a step of the stored byte.
  EXPECT_LE(worst_slack, std::sqrt(3.0) * grid.cell_m() + grid.band_m() / 255.0 + 1e-12);
}

TEST(ToolClearanceGrid, NeverOverstatesTheDistanceToTheResectoscope) {
  expect_lower_bound(combined_resectoscope_mesh(generate_resectoscope()), std::size_t{1} << 16);
}

TEST(ToolClearanceGrid, NeverOverstatesTheDistanceToTheLoopWithFineCells) {
  expect_lower_bound(generate_resectoscope().loop, std::size_t{1} << 18);
}

TEST(ToolClearanceGrid, AnEmptyMeshGivesAnEmptyGrid) {
  ToolClearanceGrid grid;
  grid.build(TriangleMesh{});
  EXPECT_TRUE(grid.empty());
}


TEST(ToolClearanceGrid, HugeCoordinatesKeepTheCellCountBounded) {
  // At 1e150 the box's volume overflowed, the cell side became infinite and the cell count NaN:
  // the build spun forever. The cell side is now taken per axis, and a count past the cap is capped.
  for (const double side : {1e150, 1e155, 1e300}) {
    ToolClearanceGrid grid;
    grid.build(testing::corner_tetrahedron(side), 4096);
    EXPECT_LE(grid.cell_count(), 16u * 4096u) << side;  // the asked-for cells plus the band's 8 around them
  }
}

TEST(ToolClearanceGrid, TinyToolsKeepTheCellCountBounded) {
  // Below 1e-102 a side the box's volume underflowed to zero, and so did the cell side: a grid of
  // zero cells had 65,537 a side, and `resecto collide` with a tool 1e-110 mm across ran out of memory.
  for (const double side : {1e-110, 1e-160, 1e-300, 5e-324}) {
    ToolClearanceGrid grid;
    grid.build(testing::corner_tetrahedron(side), 4096);
    EXPECT_LE(grid.cell_count(), 16u * 4096u) << side;
    EXPECT_GT(grid.cell_count(), 0u) << side;
  }
}

}  // namespace
}  // namespace resecto
