// closest_point_on_triangle against a brute-force oracle: the nearest of a dense barycentric grid
// over the triangle, for points in every Voronoi region and for degenerate triangles; and the
// four-at-a-time squared distances against it bit for bit.
#include "rtcore/geometry/closest_point.h"

#include <gtest/gtest.h>

#include <cstring>
#include <random>

#include "rtcore/base/cpu_features.h"

namespace resecto {
namespace {

/// The closest of (n+1)(n+2)/2 points spread evenly over the closed triangle.
Vec3 closest_by_sampling(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c, int n) {
  Vec3 best = a;
  double best2 = glm::dot(p - a, p - a);
  for (int i = 0; i <= n; ++i) {
    for (int j = 0; i + j <= n; ++j) {
      const double u = static_cast<double>(i) / n, v = static_cast<double>(j) / n;
      const Vec3 q = a + u * (b - a) + v * (c - a);
      const double d2 = glm::dot(p - q, p - q);
      if (d2 < best2) {
        best2 = d2;
        best = q;
      }
    }
  }
  return best;
}

TEST(ClosestPoint, MatchesDenseSamplingForRandomPointsAndTriangles) {
  std::mt19937_64 random(7);
  std::uniform_real_distribution<double> coordinate(-1.0, 1.0);
  auto point = [&] { return Vec3(coordinate(random), coordinate(random), coordinate(random)); };
  const int n = 400;  // grid spacing ~1/400 of an edge
  for (int trial = 0; trial < 300; ++trial) {
    const Vec3 a = point(), b = point(), c = point(), p = 2.0 * point();
    const Vec3 exact = closest_point_on_triangle(p, a, b, c);
    const Vec3 sampled = closest_by_sampling(p, a, b, c, n);
    const double exact_d = length(p - exact), sampled_d = length(p - sampled);
    // The exact point is never further than any sample, and the grid comes within its spacing.
    EXPECT_LE(exact_d, sampled_d + 1e-12) << "trial " << trial;
    EXPECT_GE(exact_d, sampled_d - 4.0 / n) << "trial " << trial;
  }
}

TEST(ClosestPoint, EachVoronoiRegion) {
  const Vec3 a(0, 0, 0), b(1, 0, 0), c(0, 1, 0);
  EXPECT_EQ(closest_point_on_triangle(Vec3(-1, -1, 0), a, b, c), a);        // vertex a
  EXPECT_EQ(closest_point_on_triangle(Vec3(2, -0.5, 0), a, b, c), b);       // vertex b
  EXPECT_EQ(closest_point_on_triangle(Vec3(-0.5, 3, 0), a, b, c), c);       // vertex c
  EXPECT_EQ(closest_point_on_triangle(Vec3(0.5, -2, 0), a, b, c), Vec3(0.5, 0, 0));  // edge ab
  EXPECT_EQ(closest_point_on_triangle(Vec3(-2, 0.25, 0), a, b, c), Vec3(0, 0.25, 0));  // edge ac
  const Vec3 on_bc = closest_point_on_triangle(Vec3(1, 1, 0), a, b, c);   // edge bc
  EXPECT_NEAR(on_bc.x, 0.5, 1e-15);
  EXPECT_NEAR(on_bc.y, 0.5, 1e-15);
  const Vec3 inside = closest_point_on_triangle(Vec3(0.2, 0.3, 5), a, b, c);  // face (barycentric rounding)
  EXPECT_LT(length(inside - Vec3(0.2, 0.3, 0)), 1e-15);
}

TEST(ClosestPoint, DegenerateTrianglesFallBackToTheirEdges) {
  // Collinear corners: the closest point lies on the segment they span.
  const Vec3 a(0, 0, 0), b(1, 0, 0), c(2, 0, 0);
  const Vec3 q = closest_point_on_triangle(Vec3(1.5, 1, 0), a, b, c);
  EXPECT_NEAR(q.x, 1.5, 1e-12);
  EXPECT_NEAR(q.y, 0.0, 1e-12);
  // All three corners at one point.
  const Vec3 p(3, 4, 5);
  EXPECT_EQ(closest_point_on_triangle(Vec3(0, 0, 0), p, p, p), p);
}

TEST(ClosestPoint, FourAtATimeSquaredDistancesMatchTheOneAtATimeOnesBitForBit) {
  if (!cpu_has_avx2()) GTEST_SKIP() << "no AVX2 on this processor: only the portable path runs";
  // Random triangles and points near them reach every region; then degenerate ones (collinear, one
  // point, two corners equal) and a point on a corner, among ordinary ones in the same groups of four.
  std::mt19937_64 random(29);
  std::uniform_real_distribution<double> coordinate(-1.0, 1.0);
  std::vector<Vec3> positions;
  std::vector<std::array<std::uint32_t, 3>> triangles;
  const auto add = [&](const Vec3& a, const Vec3& b, const Vec3& c) {
    const auto first = static_cast<std::uint32_t>(positions.size());
    positions.insert(positions.end(), {a, b, c});
    triangles.push_back({first, first + 1, first + 2});
  };
  const auto any = [&] { return Vec3(coordinate(random), coordinate(random), coordinate(random)); };
  for (int t = 0; t < 2000; ++t) add(any(), any(), any());
  add(Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(2, 0, 0));
  add(Vec3(0.3, 0.3, 0.3), Vec3(0.3, 0.3, 0.3), Vec3(0.3, 0.3, 0.3));
  add(Vec3(0, 0, 0), Vec3(0, 0, 0), Vec3(0, 1, 0));
  add(Vec3(0.1, 0.2, 0.3), Vec3(0.5, -0.2, 0.1), Vec3(-0.4, 0.6, 0.2));
  std::vector<std::uint32_t> faces(triangles.size());
  for (std::uint32_t f = 0; f < faces.size(); ++f) faces[f] = static_cast<std::uint32_t>(faces.size()) - 1 - f;
  std::vector<Vec3> points;
  for (int k = 0; k < 200; ++k) points.push_back(2.0 * any());
  points.push_back(Vec3(0.1, 0.2, 0.3));
  for (const Vec3& p : points) {
    for (const std::size_t count : {faces.size(), faces.size() - 3, std::size_t{2}}) {
      std::vector<double> portable(count), simd(count);
      squared_distances_to_triangles_portable(p, positions.data(), triangles.data(), faces.data(), count, portable.data());
      squared_distances_to_triangles_avx2(p, positions.data(), triangles.data(), faces.data(), count, simd.data());
      ASSERT_EQ(std::memcmp(portable.data(), simd.data(), count * sizeof(double)), 0) << "a point at " << p.x << ", " << p.y << ", " << p.z;
    }
  }
}

}  // namespace
}  // namespace resecto
