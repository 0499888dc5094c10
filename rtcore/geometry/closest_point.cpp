// Closest point on a triangle by Voronoi regions of its vertices, edges and face.
#include "rtcore/geometry/closest_point.h"

#include <initializer_list>

namespace resecto {

Vec3 closest_point_on_triangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = dot(ab, ap), d2 = dot(ac, ap);
  if (d1 <= 0.0 && d2 <= 0.0) return a;
  const Vec3 bp = p - b;
  const double d3 = dot(ab, bp), d4 = dot(ac, bp);
  if (d3 >= 0.0 && d4 <= d3) return b;
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) return a + (d1 / (d1 - d3)) * ab;
  const Vec3 cp = p - c;
  const double d5 = dot(ab, cp), d6 = dot(ac, cp);
  if (d6 >= 0.0 && d5 <= d6) return c;
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) return a + (d2 / (d2 - d6)) * ac;
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0) return b + ((d4 - d3) / ((d4 - d3) + (d5 - d6))) * (c - b);
  const double sum = va + vb + vc;
  if (!(sum > 0.0)) {
    // Degenerate triangle: the nearest of its three edges' closest points.
    auto on_segment = [&](const Vec3& s, const Vec3& t) {
      const Vec3 st = t - s;
      const double len2 = dot(st, st);
      const double u = len2 > 0.0 ? glm::clamp(dot(p - s, st) / len2, 0.0, 1.0) : 0.0;
      return s + u * st;
    };
    Vec3 best = on_segment(a, b);
    for (const Vec3& q : {on_segment(b, c), on_segment(a, c)}) {
      if (length_squared(q - p) < length_squared(best - p)) best = q;
    }
    return best;
  }
  const double v = vb / sum, w = vc / sum;
  return a + v * ab + w * ac;
}

}  // namespace resecto
