// The nodes' step. The AVX2 loop mirrors the portable one operation for operation: D as
// (m + ((h/2) h) R_K) + h R_C, the rescale as v * (D_old / D), the update as v + (h / D) f and
// x + h v per component, |v|^2 as (x^2 + y^2) + z^2 and the finite check's sum left to right.
// tests/rtcore/tissue/node_step_kernel_test.cpp holds them to it. Change both or neither.
#include "rtcore/tissue/node_step_kernel.h"

#include <immintrin.h>

#include <algorithm>
#include <cmath>

#include "rtcore/base/cpu_features.h"
#include "rtcore/geometry/avx2_rows.h"

namespace resecto {
namespace {

using Columns = avx2::Points4;
using avx2::load_packed_points;
using avx2::store_packed_points;

static_assert(sizeof(Vec3) == 3 * sizeof(double), "Vec3 arrays are packed (x, y, z) triples");

// Inlined into both kernels: the AVX2 one's last nodes then run as VEX code too, where a call into
// the portable function's SSE code cost each call a transition (about 8% of the step once resection
// split the loops into a few hundred spans: stepped_nodes.h).
[[gnu::always_inline]] inline NodeStepSummary step_node_range(const NodeStepArrays& nodes, double h_s, std::size_t begin, std::size_t end) {
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

}  // namespace

NodeStepSummary step_nodes_portable(const NodeStepArrays& nodes, double h_s, std::size_t begin, std::size_t end) {
  return step_node_range(nodes, h_s, begin, end);
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
    Columns v = load_packed_points(nodes.v + i);
    // A rise keeps the momentum (v *= D_old / D); elsewhere v stays as it is, bit for bit.
    const __m256d rise = _mm256_cmp_pd(d, old_d, _CMP_GT_OQ);
    const __m256d keep = _mm256_div_pd(old_d, d);
    v.x = _mm256_blendv_pd(v.x, _mm256_mul_pd(v.x, keep), rise);
    v.y = _mm256_blendv_pd(v.y, _mm256_mul_pd(v.y, keep), rise);
    v.z = _mm256_blendv_pd(v.z, _mm256_mul_pd(v.z, keep), rise);
    _mm256_storeu_pd(nodes.step_mass + i, d);
    const __m256d a = _mm256_div_pd(h, d);
    const Columns f = load_packed_points(nodes.force + i);
    v.x = _mm256_add_pd(v.x, _mm256_mul_pd(a, f.x));
    v.y = _mm256_add_pd(v.y, _mm256_mul_pd(a, f.y));
    v.z = _mm256_add_pd(v.z, _mm256_mul_pd(a, f.z));
    Columns x = load_packed_points(nodes.x + i);
    x.x = _mm256_add_pd(x.x, _mm256_mul_pd(h, v.x));
    x.y = _mm256_add_pd(x.y, _mm256_mul_pd(h, v.y));
    x.z = _mm256_add_pd(x.z, _mm256_mul_pd(h, v.z));
    store_packed_points(nodes.v + i, v);
    store_packed_points(nodes.x + i, x);
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
  const NodeStepSummary tail = step_node_range(nodes, h_s, i, end);
  summary.fastest2 = std::max({lanes[0], lanes[1], lanes[2], lanes[3], tail.fastest2});
  if (summary.first_non_finite == NodeStepSummary::kNone) summary.first_non_finite = tail.first_non_finite;
  return summary;
}

NodeStepSummary step_nodes(const NodeStepArrays& nodes, double h_s, std::size_t begin, std::size_t end) {
  return cpu_has_avx2() ? step_nodes_avx2(nodes, h_s, begin, end) : step_nodes_portable(nodes, h_s, begin, end);
}

}  // namespace resecto
