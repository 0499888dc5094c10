// The closed triangle-triangle test against hand-made configurations (crossing, coplanar, touching,
// shared edges and vertices, near misses) and against an independent oracle on random triangles.
#include "rtcore/geometry/triangle_triangle.h"

#include <gtest/gtest.h>

#include <array>
#include <random>

namespace resecto {
namespace {

using Tri = std::array<Vec3, 3>;

bool intersect(const Tri& p, const Tri& q) { return triangles_intersect(p[0], p[1], p[2], q[0], q[1], q[2]); }

// Every ordering of both triangles and of the pair must give the same answer.
void expect_symmetric(const Tri& p, const Tri& q, bool expected, const char* what) {
  const std::array<std::array<int, 3>, 6> orders{{{0, 1, 2}, {1, 2, 0}, {2, 0, 1}, {0, 2, 1}, {2, 1, 0}, {1, 0, 2}}};
  for (const auto& op : orders) {
    for (const auto& oq : orders) {
      const Tri pp{p[op[0]], p[op[1]], p[op[2]]};
      const Tri qq{q[oq[0]], q[oq[1]], q[oq[2]]};
      ASSERT_EQ(intersect(pp, qq), expected) << what;
      ASSERT_EQ(intersect(qq, pp), expected) << what << " (swapped)";
    }
  }
}

// Independent oracle: two closed triangles share a point iff an edge of one meets the other
// (coplanar containment included: the inner triangle's edges then lie in the outer one).
bool oracle(const Tri& p, const Tri& q) {
  for (int i = 0; i < 3; ++i) {
    if (segment_intersects_triangle(p[i], p[(i + 1) % 3], q[0], q[1], q[2])) return true;
    if (segment_intersects_triangle(q[i], q[(i + 1) % 3], p[0], p[1], p[2])) return true;
  }
  return false;
}

const Tri kUnit{Vec3{0, 0, 0}, Vec3{1, 0, 0}, Vec3{0, 1, 0}};

TEST(Orient3d, SignsAndExactZeroOnNearlyDegenerateInput) {
  EXPECT_EQ(orient3d({0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}), 1);
  EXPECT_EQ(orient3d({0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, -1}), -1);
  // Points on a plane with awkward coordinates: the filter cannot decide, the exact path must say 0.
  const Vec3 a{0.1, 0.2, 0.3};
  const Vec3 u{0.7, -0.3, 0.11};
  const Vec3 v{-0.2, 0.5, 0.9};
  const Vec3 b = a + u;
  const Vec3 c = a + v;
  EXPECT_EQ(orient3d(a, b, c, a), 0);
  EXPECT_EQ(orient3d(a, b, c, b), 0);
  EXPECT_EQ(orient3d(a, b, c, c), 0);
  // A point one ulp off a coordinate plane is decided correctly.
  EXPECT_EQ(orient3d({0, 0, 0}, {1e3, 0, 0}, {0, 1e3, 0}, {123.456, 654.321, 0x1p-1074}), 1);
  EXPECT_EQ(orient2d(0.1, 0.1, 0.2, 0.2, 0.3, 0.3), orient2d(0.3, 0.3, 0.2, 0.2, 0.1, 0.1) * -1);
  EXPECT_EQ(orient2d(0, 0, 1, 1, 3, 3), 0);
}

TEST(TrianglesIntersect, CrossingAndSeparated) {
  expect_symmetric(kUnit, {Vec3{0.2, 0.2, -1}, Vec3{0.2, 0.2, 1}, Vec3{3, 3, 0.5}}, true, "piercing");
  expect_symmetric(kUnit, {Vec3{0.2, 0.2, 0.5}, Vec3{0.3, 0.2, 1}, Vec3{0.2, 0.6, 1}}, false, "above");
  expect_symmetric(kUnit, {Vec3{2, 2, -1}, Vec3{2, 2, 1}, Vec3{3, 2, 0}}, false, "beside, straddling the plane");
}

TEST(TrianglesIntersect, CoplanarOverlapContainmentAndApart) {
  expect_symmetric(kUnit, {Vec3{0.5, 0.5, 0}, Vec3{-0.5, 0.5, 0}, Vec3{0.5, -0.5, 0}}, true, "coplanar overlap");
  expect_symmetric(kUnit, {Vec3{0.1, 0.1, 0}, Vec3{0.2, 0.1, 0}, Vec3{0.1, 0.2, 0}}, true, "coplanar inside");
  expect_symmetric(kUnit, {Vec3{-1, -1, 0}, Vec3{3, -1, 0}, Vec3{-1, 3, 0}}, true, "coplanar around");
  expect_symmetric(kUnit, {Vec3{0.6, 0.6, 0}, Vec3{2, 0.6, 0}, Vec3{0.6, 2, 0}}, false, "coplanar apart");
  expect_symmetric(kUnit, {Vec3{0.5, 0.5, 0}, Vec3{2, 0.5, 0}, Vec3{0.5, 2, 0}}, true, "coplanar touching at a point on the hypotenuse");
}

TEST(TrianglesIntersect, SharedEdgeAndVertex) {
  expect_symmetric(kUnit, {Vec3{0, 0, 0}, Vec3{1, 0, 0}, Vec3{0, -1, 0}}, true, "shared edge, coplanar");
  expect_symmetric(kUnit, {Vec3{0, 0, 0}, Vec3{1, 0, 0}, Vec3{0.3, -0.4, 0.8}}, true, "shared edge, folded");
  expect_symmetric(kUnit, {Vec3{0, 0, 0}, Vec3{-1, 0, 0.5}, Vec3{0, -1, 0.5}}, true, "shared vertex");
  expect_symmetric(kUnit, {Vec3{0, 0, 0}, Vec3{-1, 0, 0}, Vec3{0, -1, 0}}, true, "shared vertex, coplanar");
  // Shared vertex with awkward coordinates: the orientation of the shared vertex must be exactly 0.
  const Vec3 a{0.1, 0.7, 0.3};
  const Tri p{a, Vec3{0.9, 0.13, 0.37}, Vec3{0.21, 0.83, -0.4}};
  expect_symmetric(p, {a, Vec3{-0.5, 0.61, 0.9}, Vec3{-0.3, -0.2, 1.1}}, true, "shared awkward vertex");
  expect_symmetric(p, {p[1], p[2], Vec3{-0.5, 0.61, 0.9}}, true, "shared awkward edge");
}

TEST(TrianglesIntersect, TouchingPointsAndEdges) {
  expect_symmetric(kUnit, {Vec3{0.25, 0.25, 0}, Vec3{0.25, 0.3, 1}, Vec3{0.3, 0.25, 1}}, true, "vertex on the face");
  expect_symmetric(kUnit, {Vec3{0.5, 0.0, 0}, Vec3{0.5, -1, 1}, Vec3{0.6, -1, -1}}, true, "vertex on an edge");
  expect_symmetric(kUnit, {Vec3{0.5, -1, 0}, Vec3{0.5, 1, 0}, Vec3{0.5, 0, 1}}, true, "edge across the face");
  expect_symmetric(kUnit, {Vec3{0.5, 0, -1}, Vec3{0.5, 0, 1}, Vec3{0.5, -1, 0}}, true, "edge-edge touching, crossed");
  expect_symmetric(kUnit, {Vec3{0.5, 0.5, 0}, Vec3{1, 1, 1}, Vec3{1, 1, -1}}, true, "vertex touching the hypotenuse");
}

TEST(TrianglesIntersect, NearMissesAPicometreApart) {
  const double gap = 1e-12;
  expect_symmetric(kUnit, {Vec3{0.25, 0.25, gap}, Vec3{0.25, 0.3, 1}, Vec3{0.3, 0.25, 1}}, false, "vertex just above");
  expect_symmetric(kUnit, {Vec3{0.5, -gap, 0}, Vec3{0.5, -1, 1}, Vec3{0.6, -1, -1}}, false, "vertex just beside an edge");
  expect_symmetric(kUnit, {Vec3{0.5, -gap, -1}, Vec3{0.5, -gap, 1}, Vec3{0.5, -1, 0}}, false, "edge just beside an edge");
  expect_symmetric(kUnit, {Vec3{0.5 + gap, 0.5 + gap, 0}, Vec3{1, 1, 1}, Vec3{1, 1, -1}}, false, "vertex just off the hypotenuse");
  expect_symmetric(kUnit, {Vec3{1 + gap, 0, 0}, Vec3{2, 0, 0}, Vec3{2, 1, 0}}, false, "coplanar vertex gap");
}

TEST(TrianglesIntersect, ZeroAreaTriangleIsItsSegment) {
  expect_symmetric(kUnit, {Vec3{0.2, 0.2, -1}, Vec3{0.2, 0.2, 1}, Vec3{0.2, 0.2, 0.5}}, true, "needle through the face");
  expect_symmetric(kUnit, {Vec3{2, 2, -1}, Vec3{2, 2, 1}, Vec3{2, 2, 0.5}}, false, "needle beside");
}

// Random triangles on a small integer grid hit every degenerate case (coplanar, shared vertices,
// collinear edges, touching) many times; continuous ones cover the generic paths.
TEST(TrianglesIntersect, AgreesWithEdgeOracleOnRandomTriangles) {
  std::mt19937_64 rng(12345);
  std::uniform_int_distribution<int> grid(-2, 2);
  std::uniform_real_distribution<double> real(-1.0, 1.0);
  int hits = 0;
  int cases = 0;
  for (int n = 0; n < 200000; ++n) {
    Tri p;
    Tri q;
    const bool on_grid = n % 2 == 0;
    for (Vec3& v : p) v = on_grid ? Vec3(grid(rng), grid(rng), grid(rng) * (n % 4 == 0 ? 0 : 1)) : Vec3(real(rng), real(rng), real(rng));
    for (Vec3& v : q) v = on_grid ? Vec3(grid(rng), grid(rng), grid(rng) * (n % 4 == 0 ? 0 : 1)) : Vec3(real(rng), real(rng), real(rng));
    if (n % 8 == 1) q[0] = p[1];  // shared vertex with generic coordinates
    const bool p_flat = cross(p[1] - p[0], p[2] - p[0]) == Vec3(0.0);
    const bool q_flat = cross(q[1] - q[0], q[2] - q[0]) == Vec3(0.0);
    if (p_flat || q_flat) continue;  // the oracle needs area on both sides
    const bool expected = oracle(p, q);
    ASSERT_EQ(intersect(p, q), expected) << "case " << n;
    ASSERT_EQ(intersect(q, p), expected) << "case " << n << " swapped";
    hits += expected ? 1 : 0;
    ++cases;
  }
  EXPECT_GT(hits, cases / 10);
  EXPECT_LT(hits, cases - cases / 10);
}

}  // namespace
}  // namespace resecto
