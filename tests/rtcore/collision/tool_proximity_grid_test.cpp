// The proximity grid against brute force: at random points in and around the resectoscope's parts,
// every face within the reach is among the candidates, in ascending order; outside the grid's box
// nothing is in reach.
#include <gtest/gtest.h>

#include <random>

#include "rtcore/anatomy/resectoscope.h"
#include "rtcore/geometry/closest_point.h"
#include "rtcore/collision/tool_proximity_grid.h"
#include "scene.h"

namespace resecto {
namespace {

void expect_covers_every_face_in_reach(const TriangleMesh& mesh, double reach_m, std::size_t max_cells) {
  ToolProximityGrid grid;
  grid.build(mesh, reach_m, max_cells);
  ASSERT_GT(grid.cell_count(), 0u);
  ASSERT_LE(grid.cell_count(), 2 * max_cells) << "the cell grows to keep the count near the cap";
  std::mt19937_64 random(7);
  const Vec3 pad(2.0 * reach_m);
  std::uniform_real_distribution<double> ux(grid.lower().x - pad.x, grid.upper().x + pad.x);
  std::uniform_real_distribution<double> uy(grid.lower().y - pad.y, grid.upper().y + pad.y);
  std::uniform_real_distribution<double> uz(grid.lower().z - pad.z, grid.upper().z + pad.z);
  int in_reach = 0;
  for (int i = 0; i < 20000; ++i) {
    // Half the points on the surface's neighbourhood (a corner moved by up to the reach), half anywhere.
    Vec3 p(ux(random), uy(random), uz(random));
    if (i % 2 == 0) {
      const Vec3& corner = mesh.positions[mesh.triangles[random() % mesh.triangle_count()][0]];
      p = corner + (p - 0.5 * (grid.lower() + grid.upper())) * (reach_m / glm::length(grid.upper() - grid.lower()));
    }
    const std::span<const std::uint32_t> candidates = grid.candidates(p);
    EXPECT_TRUE(std::is_sorted(candidates.begin(), candidates.end()));
    for (std::uint32_t t = 0; t < mesh.triangle_count(); ++t) {
      const Triangle& tri = mesh.triangles[t];
      const Vec3 q = closest_point_on_triangle(p, mesh.positions[tri[0]], mesh.positions[tri[1]], mesh.positions[tri[2]]);
      if (glm::dot(p - q, p - q) > reach_m * reach_m) continue;
      ++in_reach;
      EXPECT_TRUE(std::binary_search(candidates.begin(), candidates.end(), t)) << "face " << t << " in reach of point " << i;
    }
  }
  EXPECT_GT(in_reach, 1000) << "the sample reaches the surface";
}

TEST(ToolProximityGrid, ListsEveryFaceInReachOfTheLoop) { expect_covers_every_face_in_reach(generate_resectoscope().loop, 0.0015, 1u << 18); }

TEST(ToolProximityGrid, ListsEveryFaceInReachOfTheSheathWithCoarseCells) {
  // A small cap makes the sheath's cells several millimetres: the lists grow, still complete.
  expect_covers_every_face_in_reach(generate_resectoscope().sheath, 0.0015, 4096);
}

TEST(ToolProximityGrid, AnEmptyMeshHasNoCandidates) {
  ToolProximityGrid grid;
  grid.build(TriangleMesh{}, 0.0015);
  EXPECT_TRUE(grid.candidates(Vec3(0.0)).empty());
}

TEST(ToolProximityGrid, ATinyToolKeepsTheCellCountBounded) {
  // A box whose volume underflows (sides below 1e-102) once gave zero-sized cells and 65,537 a side.
  for (const double side : {1e-110, 1e-300}) {
    ToolProximityGrid grid;
    grid.build(testing::corner_tetrahedron(side), side, 4096);
    EXPECT_LE(grid.cell_count(), 2u * 4096u) << side;
    EXPECT_FALSE(grid.candidates(Vec3(0.25 * side)).empty()) << side;
  }
}

}  // namespace
}  // namespace resecto
