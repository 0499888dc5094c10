// Closest point on a triangle by Voronoi regions of its vertices, edges and face; and its squared
// distance for many triangles, four at a time. The AVX2 loop works out every region's point in every
// lane and keeps the one the scalar test would return, with the same IEEE operations in the same
// order (dot products as (x*x + y*y) + z*z, no contraction: the build forbids it), so both paths
// give the same bits. Change both or neither.
#include "rtcore/geometry/closest_point.h"

#include <immintrin.h>

#include <initializer_list>

#include "rtcore/base/cpu_features.h"
#include "rtcore/geometry/avx2_rows.h"

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

void squared_distances_to_triangles_portable(const Vec3& p, const Vec3* positions, const std::array<std::uint32_t, 3>* triangles,
                                             const std::uint32_t* faces, std::size_t count, double* d2) {
  for (std::size_t k = 0; k < count; ++k) {
    const std::array<std::uint32_t, 3>& t = triangles[faces[k]];
    d2[k] = length_squared(p - closest_point_on_triangle(p, positions[t[0]], positions[t[1]], positions[t[2]]));
  }
}

namespace {

using avx2::dot3;
using avx2::minus;
using Point4 = avx2::Points4;

/// where ? then : otherwise, per lane, for three columns.
__attribute__((target("avx2"), always_inline)) inline Point4 choose(__m256d where, const Point4& then, const Point4& otherwise) {
  return {_mm256_blendv_pd(otherwise.x, then.x, where), _mm256_blendv_pd(otherwise.y, then.y, where), _mm256_blendv_pd(otherwise.z, then.z, where)};
}
/// s + t * d per lane and coordinate (glm's s + t * d).
__attribute__((target("avx2"), always_inline)) inline Point4 along(const Point4& s, __m256d t, const Point4& d) {
  return {_mm256_add_pd(s.x, _mm256_mul_pd(t, d.x)), _mm256_add_pd(s.y, _mm256_mul_pd(t, d.y)), _mm256_add_pd(s.z, _mm256_mul_pd(t, d.z))};
}
__attribute__((target("avx2"), always_inline)) inline __m256d dot(const Point4& a, const Point4& b) { return dot3(a.x, a.y, a.z, b.x, b.y, b.z); }
__attribute__((target("avx2"), always_inline)) inline __m256d le(__m256d a, __m256d b) { return _mm256_cmp_pd(a, b, _CMP_LE_OQ); }
__attribute__((target("avx2"), always_inline)) inline __m256d both(__m256d a, __m256d b) { return _mm256_and_pd(a, b); }

}  // namespace

__attribute__((target("avx2"))) void squared_distances_to_triangles_avx2(const Vec3& p, const Vec3* positions,
                                                                         const std::array<std::uint32_t, 3>* triangles, const std::uint32_t* faces,
                                                                         std::size_t count, double* d2) {
  const Point4 point{_mm256_set1_pd(p.x), _mm256_set1_pd(p.y), _mm256_set1_pd(p.z)};
  const __m256d zero = _mm256_setzero_pd();
  std::size_t k = 0;
  for (; k + 4 <= count; k += 4) {
    const std::array<std::uint32_t, 3>* t[4] = {&triangles[faces[k]], &triangles[faces[k + 1]], &triangles[faces[k + 2]], &triangles[faces[k + 3]]};
    const Point4 a = avx2::triangle_corners(positions, t, 0), b = avx2::triangle_corners(positions, t, 1), c = avx2::triangle_corners(positions, t, 2);
    // closest_point_on_triangle's quantities, every one in every lane.
    const Point4 ab = minus(b, a), ac = minus(c, a), ap = minus(point, a), bp = minus(point, b), cp = minus(point, c);
    const __m256d d1 = dot(ab, ap), d2_ = dot(ac, ap), d3 = dot(ab, bp), d4 = dot(ac, bp), d5 = dot(ab, cp), d6 = dot(ac, cp);
    const __m256d vc = _mm256_sub_pd(_mm256_mul_pd(d1, d4), _mm256_mul_pd(d3, d2_));
    const __m256d vb = _mm256_sub_pd(_mm256_mul_pd(d5, d2_), _mm256_mul_pd(d1, d6));
    const __m256d va = _mm256_sub_pd(_mm256_mul_pd(d3, d6), _mm256_mul_pd(d5, d4));
    const __m256d d43 = _mm256_sub_pd(d4, d3), d56 = _mm256_sub_pd(d5, d6);
    // Its regions, in the order it tests them: a lane takes the first that holds.
    const __m256d at_a = both(le(d1, zero), le(d2_, zero));
    const __m256d at_b = both(le(zero, d3), le(d4, d3));
    const __m256d on_ab = both(le(vc, zero), both(le(zero, d1), le(d3, zero)));
    const __m256d at_c = both(le(zero, d6), le(d5, d6));
    const __m256d on_ac = both(le(vb, zero), both(le(zero, d2_), le(d6, zero)));
    const __m256d on_bc = both(le(va, zero), both(le(zero, d43), le(zero, d56)));
    const __m256d sum = _mm256_add_pd(_mm256_add_pd(va, vb), vc);
    const __m256d inside = _mm256_cmp_pd(sum, zero, _CMP_GT_OQ);
    const Point4 face = along(along(a, _mm256_div_pd(vb, sum), ab), _mm256_div_pd(vc, sum), ac);
    Point4 q = choose(on_bc, along(b, _mm256_div_pd(d43, _mm256_add_pd(d43, d56)), minus(c, b)), face);
    q = choose(on_ac, along(a, _mm256_div_pd(d2_, _mm256_sub_pd(d2_, d6)), ac), q);
    q = choose(at_c, c, q);
    q = choose(on_ab, along(a, _mm256_div_pd(d1, _mm256_sub_pd(d1, d3)), ab), q);
    q = choose(at_b, b, q);
    q = choose(at_a, a, q);
    const Point4 pq = minus(point, q);
    _mm256_storeu_pd(d2 + k, dot(pq, pq));
    // A degenerate triangle's lane (no region holds and no area) takes the scalar fallback.
    const __m256d decided = _mm256_or_pd(_mm256_or_pd(_mm256_or_pd(at_a, at_b), _mm256_or_pd(on_ab, at_c)),
                                         _mm256_or_pd(_mm256_or_pd(on_ac, on_bc), inside));
    const int undecided = ~_mm256_movemask_pd(decided) & 0xf;
    if (undecided != 0) [[unlikely]] {
      for (int lane = 0; lane < 4; ++lane) {
        if (undecided & (1 << lane)) squared_distances_to_triangles_portable(p, positions, triangles, faces + k + lane, 1, d2 + k + lane);
      }
    }
  }
  squared_distances_to_triangles_portable(p, positions, triangles, faces + k, count - k, d2 + k);
}

void squared_distances_to_triangles(const Vec3& p, const Vec3* positions, const std::array<std::uint32_t, 3>* triangles, const std::uint32_t* faces,
                                    std::size_t count, double* d2) {
  if (cpu_has_avx2()) {
    squared_distances_to_triangles_avx2(p, positions, triangles, faces, count, d2);
  } else {
    squared_distances_to_triangles_portable(p, positions, triangles, faces, count, d2);
  }
}

}  // namespace resecto
