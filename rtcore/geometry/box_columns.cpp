// BoxColumns' test, portable and AVX2 (the same operations in the same order, so the same answer).
#include "rtcore/geometry/box_columns.h"

#include <immintrin.h>

#include <algorithm>

#include "rtcore/base/cpu_features.h"

namespace resecto {
namespace {

struct ColumnPointers {
  const double *lx, *ly, *lz, *hx, *hy, *hz;
};

/// How far outside [low, high] a coordinate is: max(low - c, c - high, 0).
inline double gap(double low, double c, double high) { return std::max(std::max(low - c, c - high), 0.0); }

std::size_t within_portable(const ColumnPointers& b, std::size_t from, std::size_t count, const Vec3& p, double reach2, std::uint32_t* indices) {
  std::size_t found = 0;
  for (std::size_t k = from; k < count; ++k) {
    const double gx = gap(b.lx[k], p.x, b.hx[k]), gy = gap(b.ly[k], p.y, b.hy[k]), gz = gap(b.lz[k], p.z, b.hz[k]);
    if (gx * gx + gy * gy + gz * gz <= reach2) indices[found++] = static_cast<std::uint32_t>(k);
  }
  return found;
}

/// Four boxes' gaps along one axis, from their columns at k.
__attribute__((target("avx2"), always_inline)) inline __m256d lane_gap(const double* low, const double* high, std::size_t k, __m256d c) {
  return _mm256_max_pd(_mm256_max_pd(_mm256_sub_pd(_mm256_loadu_pd(low + k), c), _mm256_sub_pd(c, _mm256_loadu_pd(high + k))), _mm256_setzero_pd());
}

__attribute__((target("avx2"))) std::size_t within_avx2(const ColumnPointers& b, std::size_t count, const Vec3& p, double reach2,
                                                        std::uint32_t* indices) {
  const __m256d px = _mm256_set1_pd(p.x), py = _mm256_set1_pd(p.y), pz = _mm256_set1_pd(p.z);
  const __m256d reach = _mm256_set1_pd(reach2);
  std::size_t found = 0, k = 0;
  for (; k + 4 <= count; k += 4) {
    const __m256d gx = lane_gap(b.lx, b.hx, k, px), gy = lane_gap(b.ly, b.hy, k, py), gz = lane_gap(b.lz, b.hz, k, pz);
    const __m256d d2 = _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(gx, gx), _mm256_mul_pd(gy, gy)), _mm256_mul_pd(gz, gz));
    unsigned mask = static_cast<unsigned>(_mm256_movemask_pd(_mm256_cmp_pd(d2, reach, _CMP_LE_OQ)));
    while (mask != 0) {
      indices[found++] = static_cast<std::uint32_t>(k + static_cast<std::size_t>(__builtin_ctz(mask)));
      mask &= mask - 1;
    }
  }
  return found + within_portable(b, k, count, p, reach2, indices + found);
}

}  // namespace

void BoxColumns::reserve(std::size_t count) {
  for (std::vector<double>* column : {&low_x_, &low_y_, &low_z_, &high_x_, &high_y_, &high_z_}) column->reserve(count);
}

void BoxColumns::clear() {
  for (std::vector<double>* column : {&low_x_, &low_y_, &low_z_, &high_x_, &high_y_, &high_z_}) column->clear();
}

void BoxColumns::push(const Vec3& low, const Vec3& high) {
  low_x_.push_back(low.x);
  low_y_.push_back(low.y);
  low_z_.push_back(low.z);
  high_x_.push_back(high.x);
  high_y_.push_back(high.y);
  high_z_.push_back(high.z);
}

std::size_t BoxColumns::within(const Vec3& p, double reach2, std::uint32_t* indices) const {
  const ColumnPointers columns{low_x_.data(), low_y_.data(), low_z_.data(), high_x_.data(), high_y_.data(), high_z_.data()};
  if (cpu_has_avx2()) return within_avx2(columns, size(), p, reach2, indices);
  return within_portable(columns, 0, size(), p, reach2, indices);
}

}  // namespace resecto
