// The nodes' step. The AVX2 loop mirrors the portable one operation for operation: D as
// (m + ((h/2) h) R_K) + h R_C, the rescale as v * (D_old / D), the update as v + (h / D) f and
// x + h v per component, |v|^2 as (x^2 + y^2) + z^2 and the finite check's sum left to right.
// tests/rtcore/tissue/node_step_kernel_test.cpp holds them to it. Change both or neither.
#include "rtcore/tissue/node_step_kernel.h"

#include <immintrin.h>

#include <algorithm>
#include <cmath>

#include "rtcore/base/cpu_features.h"

namespace resecto {
namespace {

struct Columns {
  __m256d x, y, z;
};

// Four consecutive Vec3 (twelve doubles: rows r0 = x0 y0 z0 x1, r1 = y1 z1 x2 y2, r2 = z2 x3 y3 z3)
// as columns and back: pure moves.
__attribute__((target("avx2"), always_inline)) inline Columns load_columns(const Vec3* p) {
  const double* d = &p->x;
  const __m256d r0 = _mm256_loadu_pd(d), r1 = _mm256_loadu_pd(d + 4), r2 = _mm256_loadu_pd(d + 8);
  const __m256d x0y0x2y2 = _mm256_permute2f128_pd(r0, r1, 0x30);
  const __m256d z0x1z2x3 = _mm256_permute2f128_pd(r0, r2, 0x21);
  const __m256d y1z1y3z3 = _mm256_permute2f128_pd(r1, r2, 0x30);
  return {_mm256_shuffle_pd(x0y0x2y2, z0x1z2x3, 0xA), _mm256_shuffle_pd(x0y0x2y2, y1z1y3z3, 0x5), _mm256_shuffle_pd(z0x1z2x3, y1z1y3z3, 0xA)};
}

__attribute__((target("avx2"), always_inline)) inline void store_columns(Vec3* p, const Columns& c) {
  const __m256d x0y0x2y2 = _mm256_shuffle_pd(c.x, c.y, 0x0);
  const __m256d z0x1z2x3 = _mm256_shuffle_pd(c.z, c.x, 0xA);
  const __m256d y1z1y3z3 = _mm256_shuffle_pd(c.y, c.z, 0xF);
  double* d = &p->x;
  _mm256_storeu_pd(d, _mm256_permute2f128_pd(x0y0x2y2, z0x1z2x3, 0x20));
  _mm256_storeu_pd(d + 4, _mm256_permute2f128_pd(y1z1y3z3, x0y0x2y2, 0x30));
  _mm256_storeu_pd(d + 8, _mm256_permute2f128_pd(z0x1z2x3, y1z1y3z3, 0x31));
}

}  // namespace

NodeStepSummary step_nodes_portable(const NodeStepArrays& nodes, double h_s, std::size_t begin, std::size_t end) {
  NodeStepSummary summary;
  for (std::size_t i = begin; i < end; ++i) {
    const double d = nodes.mass[i] + 0.5 * h_s * h_s * nodes.stiffness_bound[i] + h_s * nodes.damping_bound[i];
    Vec3 v = nodes.v[i];
    if (d > nodes.step_mass[i]) v *= nodes.step_mass[i] / d;
    nodes.step_mass[i] = d;
    v += (h_s / d) * nodes.force[i];
    const Vec3 x = nodes.x[i] + h_s * v;
    nodes.v[i] = v;
    nodes.x[i] = x;
    summary.fastest2 = std::max(summary.fastest2, glm::dot(v, v));
    const double sum = x.x + x.y + x.z + v.x + v.y + v.z;
    if (!std::isfinite(sum) && summary.first_non_finite == NodeStepSummary::kNone) summary.first_non_finite = i;
  }
  return summary;
}

__attribute__((target("avx2"))) NodeStepSummary step_nodes_avx2(const NodeStepArrays& nodes, double h_s, std::size_t begin, std::size_t end) {
  NodeStepSummary summary;
  const __m256d h = _mm256_set1_pd(h_s), half_h2 = _mm256_set1_pd(0.5 * h_s * h_s);
  const __m256d infinity = _mm256_set1_pd(std::numeric_limits<double>::infinity());
  const __m256d sign = _mm256_set1_pd(-0.0);
  __m256d fastest2 = _mm256_setzero_pd();
  std::size_t i = begin;
  for (; i + 4 <= end; i += 4) {
    const __m256d d = _mm256_add_pd(_mm256_add_pd(_mm256_loadu_pd(nodes.mass + i), _mm256_mul_pd(half_h2, _mm256_loadu_pd(nodes.stiffness_bound + i))),
                                    _mm256_mul_pd(h, _mm256_loadu_pd(nodes.damping_bound + i)));
    const __m256d old_d = _mm256_loadu_pd(nodes.step_mass + i);
    Columns v = load_columns(nodes.v + i);
    // A rise keeps the momentum (v *= D_old / D); elsewhere v stays as it is, bit for bit.
    const __m256d rise = _mm256_cmp_pd(d, old_d, _CMP_GT_OQ);
    const __m256d keep = _mm256_div_pd(old_d, d);
    v.x = _mm256_blendv_pd(v.x, _mm256_mul_pd(v.x, keep), rise);
    v.y = _mm256_blendv_pd(v.y, _mm256_mul_pd(v.y, keep), rise);
    v.z = _mm256_blendv_pd(v.z, _mm256_mul_pd(v.z, keep), rise);
    _mm256_storeu_pd(nodes.step_mass + i, d);
    const __m256d a = _mm256_div_pd(h, d);
    const Columns f = load_columns(nodes.force + i);
    v.x = _mm256_add_pd(v.x, _mm256_mul_pd(a, f.x));
    v.y = _mm256_add_pd(v.y, _mm256_mul_pd(a, f.y));
    v.z = _mm256_add_pd(v.z, _mm256_mul_pd(a, f.z));
    Columns x = load_columns(nodes.x + i);
    x.x = _mm256_add_pd(x.x, _mm256_mul_pd(h, v.x));
    x.y = _mm256_add_pd(x.y, _mm256_mul_pd(h, v.y));
    x.z = _mm256_add_pd(x.z, _mm256_mul_pd(h, v.z));
    store_columns(nodes.v + i, v);
    store_columns(nodes.x + i, x);
    // std::max(fastest, |v|^2) keeps `fastest` when |v|^2 is NaN; so does max_pd with it second.
    const __m256d speed2 = _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(v.x, v.x), _mm256_mul_pd(v.y, v.y)), _mm256_mul_pd(v.z, v.z));
    fastest2 = _mm256_max_pd(speed2, fastest2);
    const __m256d sum = _mm256_add_pd(
        _mm256_add_pd(_mm256_add_pd(_mm256_add_pd(_mm256_add_pd(x.x, x.y), x.z), v.x), v.y), v.z);
    // Not finite: |sum| is not below infinity (a NaN compares false).
    const int non_finite = _mm256_movemask_pd(_mm256_cmp_pd(_mm256_andnot_pd(sign, sum), infinity, _CMP_NLT_UQ));
    if (non_finite != 0 && summary.first_non_finite == NodeStepSummary::kNone) [[unlikely]] {
      summary.first_non_finite = i + static_cast<std::size_t>(__builtin_ctz(static_cast<unsigned>(non_finite)));
    }
  }
  alignas(32) double lanes[4];
  _mm256_store_pd(lanes, fastest2);
  const NodeStepSummary tail = step_nodes_portable(nodes, h_s, i, end);
  summary.fastest2 = std::max({lanes[0], lanes[1], lanes[2], lanes[3], tail.fastest2});
  if (summary.first_non_finite == NodeStepSummary::kNone) summary.first_non_finite = tail.first_non_finite;
  return summary;
}

NodeStepSummary step_nodes(const NodeStepArrays& nodes, double h_s, std::size_t begin, std::size_t end) {
  return cpu_has_avx2() ? step_nodes_avx2(nodes, h_s, begin, end) : step_nodes_portable(nodes, h_s, begin, end);
}

}  // namespace resecto
