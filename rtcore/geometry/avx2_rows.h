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

/// A point's (x, y, z, 0) and back, with plain 16- and 8-byte moves. A masked store spans 32 bytes, so
/// on AMD processors a load of the next point waits until it leaves the store buffer (no forwarding);
/// a pass that reads and writes consecutive points, such as the node sums, stalls on every point.
__attribute__((target("avx2"), always_inline)) inline __m256d load_xyz(const Vec3& p) {
  return _mm256_insertf128_pd(_mm256_castpd128_pd256(_mm_loadu_pd(&p.x)), _mm_load_sd(&p.z), 1);
}
__attribute__((target("avx2"), always_inline)) inline void store_xyz(Vec3& p, __m256d row) {
  _mm_storeu_pd(&p.x, _mm256_castpd256_pd128(row));
  _mm_store_sd(&p.z, _mm256_extractf128_pd(row, 1));
}

/// Four (x, y, z, _) rows as three columns: transpose4 without the fourth column's shuffle.
__attribute__((target("avx2"), always_inline)) inline Points4 points_of(__m256d r0, __m256d r1, __m256d r2, __m256d r3) {
  const __m256d xz01 = _mm256_unpacklo_pd(r0, r1), y01 = _mm256_unpackhi_pd(r0, r1);
  const __m256d xz23 = _mm256_unpacklo_pd(r2, r3), y23 = _mm256_unpackhi_pd(r2, r3);
  return {_mm256_permute2f128_pd(xz01, xz23, 0x20), _mm256_permute2f128_pd(y01, y23, 0x20), _mm256_permute2f128_pd(xz01, xz23, 0x31)};
}

/// Four consecutive packed (x, y, z) triples, twelve doubles (rows r0 = x0 y0 z0 x1, r1 = y1 z1 x2 y2,
/// r2 = z2 x3 y3 z3), as three columns, and back: three unaligned loads or stores and six shuffles.
__attribute__((target("avx2"), always_inline)) inline Points4 load_packed_points(const Vec3* p) {
  const double* d = &p->x;
  const __m256d r0 = _mm256_loadu_pd(d), r1 = _mm256_loadu_pd(d + 4), r2 = _mm256_loadu_pd(d + 8);
  const __m256d x0y0x2y2 = _mm256_permute2f128_pd(r0, r1, 0x30);
  const __m256d z0x1z2x3 = _mm256_permute2f128_pd(r0, r2, 0x21);
  const __m256d y1z1y3z3 = _mm256_permute2f128_pd(r1, r2, 0x30);
  return {_mm256_shuffle_pd(x0y0x2y2, z0x1z2x3, 0xA), _mm256_shuffle_pd(x0y0x2y2, y1z1y3z3, 0x5), _mm256_shuffle_pd(z0x1z2x3, y1z1y3z3, 0xA)};
}
__attribute__((target("avx2"), always_inline)) inline void store_packed_points(Vec3* p, const Points4& c) {
  const __m256d x0y0x2y2 = _mm256_shuffle_pd(c.x, c.y, 0x0);
  const __m256d z0x1z2x3 = _mm256_shuffle_pd(c.z, c.x, 0xA);
  const __m256d y1z1y3z3 = _mm256_shuffle_pd(c.y, c.z, 0xF);
  double* d = &p->x;
  _mm256_storeu_pd(d, _mm256_permute2f128_pd(x0y0x2y2, z0x1z2x3, 0x20));
  _mm256_storeu_pd(d + 4, _mm256_permute2f128_pd(y1z1y3z3, x0y0x2y2, 0x30));
  _mm256_storeu_pd(d + 8, _mm256_permute2f128_pd(z0x1z2x3, y1z1y3z3, 0x31));
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
