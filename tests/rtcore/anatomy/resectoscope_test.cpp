// The benchmark resectoscope: the paper's exact triangle counts, valid closed parts, the dimensions
// DESIGN.md gives, and loop travel as a pure translation.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "rtcore/anatomy/resectoscope.h"
#include "rtcore/mesh/mesh_validation.h"

namespace resecto {
namespace {

TEST(Resectoscope, HasThePapersTriangleCounts) {
  const ResectoscopeModel tool = generate_resectoscope();
  EXPECT_EQ(tool.sheath.triangle_count(), 158u);
  EXPECT_EQ(tool.loop.triangle_count(), 330u);
  const TriangleMesh combined = combined_resectoscope_mesh(tool);
  EXPECT_EQ(combined.triangle_count(), 488u);
  // The first 158 faces are the sheath.
  for (std::size_t f = 0; f < 158; ++f) EXPECT_EQ(combined.triangles[f], tool.sheath.triangles[f]);
}

TEST(Resectoscope, BothPartsAreValidClosedSurfaces) {
  for (double travel_m : {0.0, 0.012, 0.036}) {
    ResectoscopeShape shape;
    shape.loop_travel_m = travel_m;
    const ResectoscopeModel tool = generate_resectoscope(shape);
    for (const TriangleMesh* part : {&tool.sheath, &tool.loop}) {
      Result<SurfaceReport> report = validate_closed_surface(*part);
      ASSERT_TRUE(report) << report.error();
      EXPECT_EQ(report->genus, 0);
      EXPECT_EQ(report->components, 1);
    }
  }
}

TEST(Resectoscope, DimensionsMatchTheDesign) {
  const ResectoscopeShape shape;
  const ResectoscopeModel tool = generate_resectoscope(shape);
  const Aabb sheath = bounding_box(tool.sheath);
  EXPECT_NEAR(sheath.size().x, 0.00867, 1e-5);       // 26 Fr
  EXPECT_NEAR(sheath.max.z, 0.0, 1e-12);             // tip at the origin
  EXPECT_NEAR(sheath.min.z, -shape.sheath_length_m, 1e-12);
  const Aabb loop = bounding_box(tool.loop);
  EXPECT_NEAR(loop.size().x, shape.loop_span_m + shape.wire_diameter_m, 2e-4);  // about 6 mm across
  // The wire hangs to within 0.1 mm of the sheath's outline, and never beyond it.
  EXPECT_GT(loop.min.y, -0.5 * shape.sheath_diameter_m);
  EXPECT_LT(loop.min.y, -0.5 * shape.sheath_diameter_m + 1e-4);
  // Retracted, the whole loop lies inside the sheath, behind its tip (in the beak's slot), so a
  // stroke drawn fully back has closed against the sheath.
  EXPECT_LT(loop.max.z, 0.0);
  for (const Vec3& p : tool.loop.positions) EXPECT_LT(std::hypot(p.x, p.y), 0.5 * shape.sheath_diameter_m);
}

TEST(Resectoscope, TheWireLeavesTheSheathAtHalfAMillimetreOfTravel) {
  ResectoscopeShape shape;
  for (double travel_m : {0.0, 0.0005, 0.012}) {
    shape.loop_travel_m = travel_m;
    const std::vector<Vec3> arc = loop_cutting_arc(shape);
    for (const Vec3& p : arc) EXPECT_NEAR(p.z, travel_m - 0.0005, 1e-15) << "travel " << travel_m;
  }
  // Out of the sheath, every point of the loop behind the tip (its arms) stays inside it.
  shape.loop_travel_m = 0.012;
  for (const Vec3& p : generate_resectoscope(shape).loop.positions) {
    if (p.z < 0.0) {
      EXPECT_LT(std::hypot(p.x, p.y), 0.5 * shape.sheath_diameter_m);
    }
  }
}

TEST(Resectoscope, LoopTravelTranslatesTheLoopAlongTheAxis) {
  ResectoscopeShape shape;
  const ResectoscopeModel home = generate_resectoscope(shape);
  shape.loop_travel_m = 0.036;
  const ResectoscopeModel out = generate_resectoscope(shape);
  ASSERT_EQ(home.loop.positions.size(), out.loop.positions.size());
  for (std::size_t v = 0; v < home.loop.positions.size(); ++v) {
    const Vec3 d = out.loop.positions[v] - home.loop.positions[v];
    EXPECT_NEAR(d.x, 0.0, 1e-12);
    EXPECT_NEAR(d.y, 0.0, 1e-12);
    EXPECT_NEAR(d.z, 0.036, 1e-12);
  }
  EXPECT_EQ(home.sheath.positions, out.sheath.positions);
}

}  // namespace
}  // namespace resecto
