// Spring force kernels and the node sums. Each AVX2 loop mirrors its portable one operation for
// operation (same operands, same association: dot products as (x + y) + z, sums in incidence order),
// which is what keeps them bit-identical; tests/rtcore/tissue/spring_kernel_test.cpp holds them to
// it. Change both or neither.
#include "rtcore/tissue/spring_kernel.h"

#include <immintrin.h>

#include <algorithm>
#include <bit>
#include <cmath>

#include "rtcore/geometry/avx2_rows.h"

namespace resecto {
namespace {

using Columns = avx2::Points4;
using avx2::load_point;

/// Node j's row minus node i's row of `p` for four springs, as columns: the same subtractions the
/// portable loop does per component, done before the transpose (gathers are slow on this class of
/// processor, and rows subtract with one instruction). Load is load_point, or a plain 32-byte load
/// where the node is not the last: its fourth lane (the next node's x) is never used.
template <class Load>
__attribute__((target("avx2"), always_inline)) inline Columns differences(const Vec3* p, const std::uint32_t* i, const std::uint32_t* j, Load load) {
  return avx2::points_of(_mm256_sub_pd(load(p[j[0]]), load(p[i[0]])), _mm256_sub_pd(load(p[j[1]]), load(p[i[1]])),
                         _mm256_sub_pd(load(p[j[2]]), load(p[i[2]])), _mm256_sub_pd(load(p[j[3]]), load(p[i[3]])));
}

__attribute__((target("avx2"), always_inline)) inline __m256d load_row_and_next(const Vec3& p) { return _mm256_loadu_pd(&p.x); }

/// Four springs' force columns back to rows (x, y, z, 0), stored at f[0..3]: pure moves.
__attribute__((target("avx2"), always_inline)) inline void store_rows(SpringForce* f, __m256d fx, __m256d fy, __m256d fz) {
  const __m256d zero = _mm256_setzero_pd();
  const __m256d xy02 = _mm256_unpacklo_pd(fx, fy), xy13 = _mm256_unpackhi_pd(fx, fy);  // (x0 y0 x2 y2), (x1 y1 x3 y3)
  const __m256d z02 = _mm256_unpacklo_pd(fz, zero), z13 = _mm256_unpackhi_pd(fz, zero);
  _mm256_store_pd(&f[0].x, _mm256_permute2f128_pd(xy02, z02, 0x20));
  _mm256_store_pd(&f[1].x, _mm256_permute2f128_pd(xy13, z13, 0x20));
  _mm256_store_pd(&f[2].x, _mm256_permute2f128_pd(xy02, z02, 0x31));
  _mm256_store_pd(&f[3].x, _mm256_permute2f128_pd(xy13, z13, 0x31));
}

}  // namespace

std::size_t spring_forces_portable(SpringArrays& springs, const Vec3* x, const Vec3* v, std::size_t begin, std::size_t end,
                                   std::uint32_t* compressed_out) {
  std::size_t compressed = 0;
  for (std::size_t s = begin; s < end; ++s) {
    const Vec3& xi = x[springs.i[s]];
    const Vec3& xj = x[springs.j[s]];
    const double dx = xj.x - xi.x, dy = xj.y - xi.y, dz = xj.z - xi.z;
    const double length = std::sqrt((dx * dx + dy * dy) + dz * dz);
    const double inverse_length = length > 0.0 ? 1.0 / length : 0.0;
    const double ux = dx * inverse_length, uy = dy * inverse_length, uz = dz * inverse_length;
    const double stretch = length - springs.rest_m[s];
    const Vec3& vi = v[springs.i[s]];
    const Vec3& vj = v[springs.j[s]];
    const double along = ((vj.x - vi.x) * ux + (vj.y - vi.y) * uy) + (vj.z - vi.z) * uz;
    const double magnitude = springs.k[s] * stretch + springs.c[s] * along;
    springs.f[s] = {magnitude * ux, magnitude * uy, magnitude * uz, 0.0};
    if (length > 0.0 && 2.0 * length < springs.rest_m[s]) [[unlikely]] compressed_out[compressed++] = static_cast<std::uint32_t>(s);
  }
  return compressed;
}

__attribute__((target("avx2"))) std::size_t spring_forces_avx2(SpringArrays& springs, const Vec3* x, const Vec3* v, std::size_t node_count,
                                                               std::size_t begin, std::size_t end, std::uint32_t* compressed_out) {
  const __m256d zero = _mm256_setzero_pd(), one = _mm256_set1_pd(1.0), two = _mm256_set1_pd(2.0);
  std::size_t compressed = 0;
  std::size_t s = begin;
  // A masked load costs a second micro-op on the ports the arithmetic needs; only four springs that
  // hold the last node need it (as i or j: refinement's springs have i > j).
  const __m128i last_node = _mm_set1_epi32(node_count == 0 ? 0 : static_cast<int>(node_count - 1));
  for (; s + 4 <= end; s += 4) {
    const std::uint32_t* i = springs.i.data() + s;
    const std::uint32_t* j = springs.j.data() + s;
    const __m128i larger = _mm_max_epu32(_mm_loadu_si128(reinterpret_cast<const __m128i*>(i)), _mm_loadu_si128(reinterpret_cast<const __m128i*>(j)));
    const bool whole_rows = _mm_movemask_epi8(_mm_cmplt_epi32(larger, last_node)) == 0xFFFF;
    const Columns d = whole_rows ? differences(x, i, j, load_row_and_next) : differences(x, i, j, load_point);
    const __m256d dx = d.x, dy = d.y, dz = d.z;
    const __m256d length =
        _mm256_sqrt_pd(_mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(dx, dx), _mm256_mul_pd(dy, dy)), _mm256_mul_pd(dz, dz)));
    // length > 0 ? 1 / length : 0 (a NaN length compares false too, as in the portable loop).
    const __m256d positive = _mm256_cmp_pd(length, zero, _CMP_GT_OQ);
    const __m256d inverse_length = _mm256_and_pd(_mm256_div_pd(one, length), positive);
    const __m256d ux = _mm256_mul_pd(dx, inverse_length);
    const __m256d uy = _mm256_mul_pd(dy, inverse_length);
    const __m256d uz = _mm256_mul_pd(dz, inverse_length);
    const __m256d rest = _mm256_loadu_pd(springs.rest_m.data() + s);
    const __m256d stretch = _mm256_sub_pd(length, rest);
    const Columns dv = whole_rows ? differences(v, i, j, load_row_and_next) : differences(v, i, j, load_point);
    const __m256d dvx = dv.x, dvy = dv.y, dvz = dv.z;
    const __m256d along = _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(dvx, ux), _mm256_mul_pd(dvy, uy)), _mm256_mul_pd(dvz, uz));
    const __m256d magnitude = _mm256_add_pd(_mm256_mul_pd(_mm256_loadu_pd(springs.k.data() + s), stretch),
                                            _mm256_mul_pd(_mm256_loadu_pd(springs.c.data() + s), along));
    store_rows(springs.f.data() + s, _mm256_mul_pd(magnitude, ux), _mm256_mul_pd(magnitude, uy), _mm256_mul_pd(magnitude, uz));
    const __m256d short_spring = _mm256_and_pd(positive, _mm256_cmp_pd(_mm256_mul_pd(two, length), rest, _CMP_LT_OQ));
    for (unsigned lanes = static_cast<unsigned>(_mm256_movemask_pd(short_spring)); lanes != 0; lanes &= lanes - 1) [[unlikely]] {
      compressed_out[compressed++] = static_cast<std::uint32_t>(s + static_cast<std::size_t>(std::countr_zero(lanes)));
    }
  }
  return compressed + spring_forces_portable(springs, x, v, s, end, compressed_out + compressed);
}

void add_spring_sums_portable(const SpringIncidence& incidence, const SpringForce* f, Vec3* force, std::size_t begin, std::size_t end) {
  for (std::size_t n = begin; n < end; ++n) {
    Vec3 sum = force[n];
    for (std::uint32_t e = incidence.second_first[n]; e < incidence.second_first[n + 1]; ++e) {
      const SpringForce& g = f[incidence.second_springs[e]];
      sum.x -= g.x, sum.y -= g.y, sum.z -= g.z;
    }
    for (std::uint32_t s = incidence.first_first[n]; s < incidence.first_first[n + 1]; ++s) sum.x += f[s].x, sum.y += f[s].y, sum.z += f[s].z;
    force[n] = sum;
  }
}

namespace {

__attribute__((target("avx2"), always_inline)) inline void add_node_sum_avx2(const SpringIncidence& incidence, const SpringForce* f, Vec3* force,
                                                                             std::size_t n) {
  __m256d sum = avx2::load_xyz(force[n]);
  for (std::uint32_t e = incidence.second_first[n]; e < incidence.second_first[n + 1]; ++e) {
    sum = _mm256_sub_pd(sum, _mm256_load_pd(&f[incidence.second_springs[e]].x));
  }
  for (std::uint32_t s = incidence.first_first[n]; s < incidence.first_first[n + 1]; ++s) sum = _mm256_add_pd(sum, _mm256_load_pd(&f[s].x));
  avx2::store_xyz(force[n], sum);
}

struct SubtractRow {
  __attribute__((target("avx2"), always_inline)) __m256d operator()(__m256d sum, __m256d row) const { return _mm256_sub_pd(sum, row); }
};
struct AddRow {
  __attribute__((target("avx2"), always_inline)) __m256d operator()(__m256d sum, __m256d row) const { return _mm256_add_pd(sum, row); }
};

/// s_k = op(s_k, row of entry e, lane k) for group entries [first, last), lane by lane in entry order.
template <class Op>
__attribute__((target("avx2"), always_inline)) inline void add_group_rows(const SpringForce* f, const std::uint32_t* entries, std::uint32_t first,
                                                                          std::uint32_t last, Op op, __m256d& s0, __m256d& s1, __m256d& s2,
                                                                          __m256d& s3) {
  for (std::uint32_t e = first; e < last; ++e) {
    const std::uint32_t* row = entries + kSpringSumGroup * e;
    s0 = op(s0, _mm256_load_pd(&f[row[0]].x));
    s1 = op(s1, _mm256_load_pd(&f[row[1]].x));
    s2 = op(s2, _mm256_load_pd(&f[row[2]].x));
    s3 = op(s3, _mm256_load_pd(&f[row[3]].x));
  }
}

}  // namespace

__attribute__((target("avx2"))) void add_spring_sums_avx2(const SpringIncidence& incidence, const SpringForce* f, Vec3* force, std::size_t begin,
                                                          std::size_t end) {
  // A node's sum is a chain of dependent adds (about twelve, four cycles each) that ends in a branch
  // on its list's length; node by node, the pass waited on that latency and mispredicted the ends.
  // A group runs its four nodes' chains side by side over lists padded to one length, each chain in
  // its node's own order, so every sum keeps its bits.
  std::size_t n = begin;
  for (; n < end && n % kSpringSumGroup != 0; ++n) add_node_sum_avx2(incidence, f, force, n);
  const std::size_t groups_end = std::min(end, incidence.group_second_first.empty() ? 0 : (incidence.group_second_first.size() - 1) * kSpringSumGroup);
  for (; n + kSpringSumGroup <= groups_end; n += kSpringSumGroup) {
    const std::size_t g = n / kSpringSumGroup;
    __m256d s0 = avx2::load_xyz(force[n]), s1 = avx2::load_xyz(force[n + 1]);
    __m256d s2 = avx2::load_xyz(force[n + 2]), s3 = avx2::load_xyz(force[n + 3]);
    // Every node's springs as node j first (subtracted), then as node i (added), as the portable pass.
    add_group_rows(f, incidence.group_second.data(), incidence.group_second_first[g], incidence.group_second_first[g + 1], SubtractRow{}, s0, s1, s2, s3);
    add_group_rows(f, incidence.group_first.data(), incidence.group_first_first[g], incidence.group_first_first[g + 1], AddRow{}, s0, s1, s2, s3);
    avx2::store_xyz(force[n], s0);
    avx2::store_xyz(force[n + 1], s1);
    avx2::store_xyz(force[n + 2], s2);
    avx2::store_xyz(force[n + 3], s3);
  }
  for (; n < end; ++n) add_node_sum_avx2(incidence, f, force, n);
}

std::size_t spring_forces(SpringArrays& springs, const Vec3* x, const Vec3* v, std::size_t node_count, std::size_t begin, std::size_t end,
                          std::uint32_t* compressed) {
  return cpu_has_avx2() ? spring_forces_avx2(springs, x, v, node_count, begin, end, compressed)
                        : spring_forces_portable(springs, x, v, begin, end, compressed);
}

void add_spring_sums(const SpringIncidence& incidence, const SpringForce* f, Vec3* force, std::size_t begin, std::size_t end) {
  if (cpu_has_avx2()) {
    add_spring_sums_avx2(incidence, f, force, begin, end);
  } else {
    add_spring_sums_portable(incidence, f, force, begin, end);
  }
}

}  // namespace resecto
