// Rows and columns for the AVX2 kernels: a point or sphere is a row (x, y, z, w) in memory, and four
// of them turn into four columns (x0..x3), (y0..y3), ... so four lanes do one point's arithmetic
// each. Pure moves: a transpose changes no bit. Include only from a file whose kernels carry
// __attribute__((target("avx2"))) and run where cpu_has_avx2().
#pragma once

#include <immintrin.h>

#include <array>
#include <cstdint>

#include "rtcore/geometry/vec3.h"

namespace resecto::avx2 {

struct Columns4 {
  __m256d x, y, z, w;
};
/// Four points as three columns.
struct Points4 {
  __m256d x, y, z;
};

/// Four rows as four columns, or four columns back as rows.
__attribute__((target("avx2"), always_inline)) inline Columns4 transpose4(__m256d r0, __m256d r1, __m256d r2, __m256d r3) {
  const __m256d xz01 = _mm256_unpacklo_pd(r0, r1), yw01 = _mm256_unpackhi_pd(r0, r1);
  const __m256d xz23 = _mm256_unpacklo_pd(r2, r3), yw23 = _mm256_unpackhi_pd(r2, r3);
  return {_mm256_permute2f128_pd(xz01, xz23, 0x20), _mm256_permute2f128_pd(yw01, yw23, 0x20), _mm256_permute2f128_pd(xz01, xz23, 0x31),
          _mm256_permute2f128_pd(yw01, yw23, 0x31)};
}

/// A point's (x, y, z, 0): a masked load, so the last point of an array never reads past it.
__attribute__((target("avx2"), always_inline)) inline __m256d load_point(const Vec3& p) {
  return _mm256_maskload_pd(&p.x, _mm256_set_epi64x(0, -1, -1, -1));
}

/// Four (x, y, z, _) rows as three columns: transpose4 without the fourth column's shuffle.
__attribute__((target("avx2"), always_inline)) inline Points4 points_of(__m256d r0, __m256d r1, __m256d r2, __m256d r3) {
  const __m256d xz01 = _mm256_unpacklo_pd(r0, r1), y01 = _mm256_unpackhi_pd(r0, r1);
  const __m256d xz23 = _mm256_unpacklo_pd(r2, r3), y23 = _mm256_unpackhi_pd(r2, r3);
  return {_mm256_permute2f128_pd(xz01, xz23, 0x20), _mm256_permute2f128_pd(y01, y23, 0x20), _mm256_permute2f128_pd(xz01, xz23, 0x31)};
}

/// Corner `corner` of four triangles (corner indices into `positions`), one triangle per lane.
__attribute__((target("avx2"), always_inline)) inline Points4 triangle_corners(const Vec3* positions, const std::array<std::uint32_t, 3>* const* t,
                                                                               int corner) {
  return points_of(load_point(positions[(*t[0])[corner]]), load_point(positions[(*t[1])[corner]]), load_point(positions[(*t[2])[corner]]),
                   load_point(positions[(*t[3])[corner]]));
}

/// a - b per lane and coordinate.
__attribute__((target("avx2"), always_inline)) inline Points4 minus(const Points4& a, const Points4& b) {
  return {_mm256_sub_pd(a.x, b.x), _mm256_sub_pd(a.y, b.y), _mm256_sub_pd(a.z, b.z)};
}

/// (x*x + y*y) + z*z per lane: glm::dot's order.
__attribute__((target("avx2"), always_inline)) inline __m256d dot3(__m256d x, __m256d y, __m256d z) {
  return _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(x, x), _mm256_mul_pd(y, y)), _mm256_mul_pd(z, z));
}

/// (ax*bx + ay*by) + az*bz per lane.
__attribute__((target("avx2"), always_inline)) inline __m256d dot3(__m256d ax, __m256d ay, __m256d az, __m256d bx, __m256d by, __m256d bz) {
  return _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(ax, bx), _mm256_mul_pd(ay, by)), _mm256_mul_pd(az, bz));
}

}  // namespace resecto::avx2
