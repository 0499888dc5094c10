// The refit kernels. Each AVX2 loop forms every value with the same IEEE operations in the same order
// as the inline functions of the header (dot products as (x*x + y*y) + z*z, maxima taken in the same
// order, no contraction: the build forbids it), so the lane width cannot change a bit. Change both or
// neither.
#include "rtcore/collision/sphere_refit_kernel.h"

#include <immintrin.h>

#include <array>
#include <cmath>

#include "rtcore/geometry/avx2_rows.h"

namespace resecto {
namespace {

using avx2::Columns4;
using avx2::dot3;
using avx2::Points4;
using avx2::transpose4;

__attribute__((target("avx2"), always_inline)) inline __m256d absolute(__m256d v) {
  return _mm256_andnot_pd(_mm256_set1_pd(-0.0), v);
}

/// inflated_sphere()'s radius for four centres and radii.
__attribute__((target("avx2"), always_inline)) inline __m256d inflated_radius(__m256d cx, __m256d cy, __m256d cz, __m256d radius) {
  const __m256d magnitude = _mm256_max_pd(_mm256_max_pd(_mm256_max_pd(absolute(cx), absolute(cy)), absolute(cz)), radius);
  return _mm256_add_pd(_mm256_mul_pd(radius, _mm256_set1_pd(1.0 + 1e-12)), _mm256_mul_pd(magnitude, _mm256_set1_pd(1e-15)));
}

/// Four spheres from columns to their rows, stored at their nodes.
__attribute__((target("avx2"), always_inline)) inline void store_spheres(Sphere* spheres, const std::int32_t* nodes, const Columns4& c) {
  const Columns4 rows = transpose4(c.x, c.y, c.z, c.w);
  _mm256_storeu_pd(&spheres[nodes[0]].center.x, rows.x);
  _mm256_storeu_pd(&spheres[nodes[1]].center.x, rows.y);
  _mm256_storeu_pd(&spheres[nodes[2]].center.x, rows.z);
  _mm256_storeu_pd(&spheres[nodes[3]].center.x, rows.w);
}

/// enclosing_sphere()'s choice per lane: a where it holds b, else b where it holds a, else the sphere over both.
__attribute__((target("avx2"), always_inline)) inline __m256d pick(__m256d a_holds_b, __m256d b_holds_a, __m256d over_both, __m256d from_a,
                                                                   __m256d from_b) {
  return _mm256_blendv_pd(_mm256_blendv_pd(over_both, from_b, b_holds_a), from_a, a_holds_b);
}

__attribute__((target("avx2"), always_inline)) inline __m256d load_sphere(const Sphere& s) { return _mm256_loadu_pd(&s.center.x); }

using FourIndices = std::array<std::int32_t, 4>;
/// The last one to three entries of `items` from `begin`, the last repeated to fill four lanes. A
/// repeated lane computes the same bits as its original and stores them to the same place, so the
/// tail runs the four-lane path rather than the one-at-a-time one (a refit's groups are mostly
/// small: a block's top heights hold one to three nodes).
inline FourIndices padded_tail(std::span<const std::int32_t> items, std::size_t begin) {
  FourIndices four{};
  for (std::size_t k = 0; k < 4; ++k) four[k] = items[std::min(begin + k, items.size() - 1)];
  return four;
}

}  // namespace

void centroid_spheres_portable(const Vec3* positions, const Triangle* corners, std::span<const std::int32_t> leaves, Sphere* spheres) {
  for (std::size_t i = 0; i < leaves.size(); ++i) {
    const Triangle& t = corners[i];
    spheres[leaves[i]] = centroid_sphere(positions[t[0]], positions[t[1]], positions[t[2]]);
  }
}

namespace {

/// Four leaves' centroid spheres, lane by lane as centroid_sphere() makes them.
__attribute__((target("avx2"), always_inline)) inline void centroid4(const Vec3* positions, const Triangle* const* t, const std::int32_t* leaf,
                                                                     Sphere* spheres) {
  const __m256d third = _mm256_set1_pd(1.0 / 3.0);
  const Points4 a = avx2::triangle_corners(positions, t, 0), b = avx2::triangle_corners(positions, t, 1), c = avx2::triangle_corners(positions, t, 2);
  // (a + b + c) * (1/3), per coordinate.
  const __m256d cx = _mm256_mul_pd(_mm256_add_pd(_mm256_add_pd(a.x, b.x), c.x), third);
  const __m256d cy = _mm256_mul_pd(_mm256_add_pd(_mm256_add_pd(a.y, b.y), c.y), third);
  const __m256d cz = _mm256_mul_pd(_mm256_add_pd(_mm256_add_pd(a.z, b.z), c.z), third);
  const __m256d da = dot3(_mm256_sub_pd(a.x, cx), _mm256_sub_pd(a.y, cy), _mm256_sub_pd(a.z, cz));
  const __m256d db = dot3(_mm256_sub_pd(b.x, cx), _mm256_sub_pd(b.y, cy), _mm256_sub_pd(b.z, cz));
  const __m256d dc = dot3(_mm256_sub_pd(c.x, cx), _mm256_sub_pd(c.y, cy), _mm256_sub_pd(c.z, cz));
  const __m256d radius = _mm256_sqrt_pd(_mm256_max_pd(_mm256_max_pd(da, db), dc));
  store_spheres(spheres, leaf, {cx, cy, cz, inflated_radius(cx, cy, cz, radius)});
}

/// Entries i .. i+3 of an array of `count`, the last repeated past its end (as padded_tail() repeats the indices).
template <class T>
std::array<const T*, 4> padded_four(const T* items, std::size_t i, std::size_t count) {
  std::array<const T*, 4> four{};
  for (std::size_t k = 0; k < 4; ++k) four[k] = items + std::min(i + k, count - 1);
  return four;
}

}  // namespace

__attribute__((target("avx2"))) void centroid_spheres_avx2(const Vec3* positions, const Triangle* corners, std::span<const std::int32_t> leaves,
                                                           Sphere* spheres) {
  const std::size_t count = leaves.size();
  const std::int32_t* leaf = leaves.data();
  // The corners come in order; the positions they index lie scattered, loaded some leaves ahead.
  constexpr std::size_t kCornersAhead = 8;
  std::size_t i = 0;
  for (; i + 4 <= count; i += 4) {
    for (std::size_t k = i + kCornersAhead; k < std::min(i + 4 + kCornersAhead, count); ++k) {
      __builtin_prefetch(positions + corners[k][0]);
      __builtin_prefetch(positions + corners[k][1]);
      __builtin_prefetch(positions + corners[k][2]);
    }
    const Triangle* t[4] = {corners + i, corners + i + 1, corners + i + 2, corners + i + 3};
    centroid4(positions, t, leaf + i, spheres);
  }
  if (i < count) {
    const FourIndices tail = padded_tail(leaves, i);
    centroid4(positions, padded_four(corners, i, count).data(), tail.data(), spheres);
  }
}

void centroid_spheres(const Vec3* positions, const Triangle* corners, std::span<const std::int32_t> leaves, Sphere* spheres) {
  if (cpu_has_avx2()) {
    centroid_spheres_avx2(positions, corners, leaves, spheres);
  } else {
    centroid_spheres_portable(positions, corners, leaves, spheres);
  }
}

void sliced_piece_spheres_portable(const Vec3* positions, const SliceOperands* operands, std::span<const std::int32_t> leaves, Sphere* spheres) {
  for (std::size_t i = 0; i < leaves.size(); ++i) {
    const SliceOperands& o = operands[i];
    spheres[leaves[i]] = SphereTree::slice_sphere(positions[o.corners[0]], positions[o.corners[1]], positions[o.corners[2]], o.t0, o.t1);
  }
}

namespace {

__attribute__((target("avx2"), always_inline)) inline Points4 corner_of(const Vec3* positions, const SliceOperands* const* o, int k) {
  return avx2::points_of(avx2::load_point(positions[o[0]->corners[k]]), avx2::load_point(positions[o[1]->corners[k]]),
                         avx2::load_point(positions[o[2]->corners[k]]), avx2::load_point(positions[o[3]->corners[k]]));
}
/// x * (1 - t) + b * t per coordinate (glm's order).
__attribute__((target("avx2"), always_inline)) inline Points4 lerp(const Points4& x, const Points4& b, __m256d t) {
  const __m256d s = _mm256_sub_pd(_mm256_set1_pd(1.0), t);
  return {_mm256_add_pd(_mm256_mul_pd(x.x, s), _mm256_mul_pd(b.x, t)), _mm256_add_pd(_mm256_mul_pd(x.y, s), _mm256_mul_pd(b.y, t)),
          _mm256_add_pd(_mm256_mul_pd(x.z, s), _mm256_mul_pd(b.z, t))};
}
/// The largest squared distance from c to the four points, taken as std::max takes it from 0.
__attribute__((target("avx2"), always_inline)) inline __m256d reach2(const std::array<Points4, 4>& points, const Points4& c) {
  __m256d r2 = _mm256_setzero_pd();
  for (const Points4& p : points) {
    const Points4 d = avx2::minus(p, c);
    r2 = _mm256_max_pd(dot3(d.x, d.y, d.z), r2);
  }
  return r2;
}

/// Four sliced pieces' spheres, lane by lane as SphereTree::slice_sphere() makes them.
__attribute__((target("avx2"), always_inline)) inline void slice4(const Vec3* positions, const SliceOperands* const* o, const std::int32_t* leaf,
                                                                  Sphere* spheres) {
  const Points4 b = corner_of(positions, o, 0), x = corner_of(positions, o, 1), y = corner_of(positions, o, 2);
  const __m256d t0 = _mm256_set_pd(o[3]->t0, o[2]->t0, o[1]->t0, o[0]->t0), t1 = _mm256_set_pd(o[3]->t1, o[2]->t1, o[1]->t1, o[0]->t1);
  // sphere_around() of the slab's four corners: the box centre's sphere, or the centroid's if smaller.
  const std::array<Points4, 4> p{lerp(x, b, t0), lerp(y, b, t0), lerp(x, b, t1), lerp(y, b, t1)};
  Points4 low = p[0], high = p[0];
  Points4 sum{_mm256_setzero_pd(), _mm256_setzero_pd(), _mm256_setzero_pd()};
  for (const Points4& q : p) {
    low = {_mm256_min_pd(q.x, low.x), _mm256_min_pd(q.y, low.y), _mm256_min_pd(q.z, low.z)};
    high = {_mm256_max_pd(q.x, high.x), _mm256_max_pd(q.y, high.y), _mm256_max_pd(q.z, high.z)};
    sum = {_mm256_add_pd(sum.x, q.x), _mm256_add_pd(sum.y, q.y), _mm256_add_pd(sum.z, q.z)};
  }
  const __m256d half = _mm256_set1_pd(0.5), quarter = _mm256_set1_pd(0.25);
  const Points4 box{_mm256_mul_pd(half, _mm256_add_pd(low.x, high.x)), _mm256_mul_pd(half, _mm256_add_pd(low.y, high.y)),
                    _mm256_mul_pd(half, _mm256_add_pd(low.z, high.z))};
  // sum / 4 as sphere_around() divides: a power of two scales exactly, so the product has its bits.
  const Points4 centroid{_mm256_mul_pd(sum.x, quarter), _mm256_mul_pd(sum.y, quarter), _mm256_mul_pd(sum.z, quarter)};
  const __m256d infinity = _mm256_set1_pd(INFINITY);
  const __m256d box_r = _mm256_sqrt_pd(reach2(p, box)), centroid_r = _mm256_sqrt_pd(reach2(p, centroid));
  const __m256d best_r = _mm256_blendv_pd(infinity, box_r, _mm256_cmp_pd(box_r, infinity, _CMP_LT_OQ));
  const __m256d take_centroid = _mm256_cmp_pd(centroid_r, best_r, _CMP_LT_OQ);
  const __m256d cx = _mm256_blendv_pd(box.x, centroid.x, take_centroid), cy = _mm256_blendv_pd(box.y, centroid.y, take_centroid);
  const __m256d cz = _mm256_blendv_pd(box.z, centroid.z, take_centroid), r = _mm256_blendv_pd(best_r, centroid_r, take_centroid);
  store_spheres(spheres, leaf, {cx, cy, cz, inflated_radius(cx, cy, cz, r)});
}

}  // namespace

__attribute__((target("avx2"))) void sliced_piece_spheres_avx2(const Vec3* positions, const SliceOperands* operands, std::span<const std::int32_t> leaves,
                                                               Sphere* spheres) {
  std::size_t i = 0;
  for (; i + 4 <= leaves.size(); i += 4) {
    const SliceOperands* four[4] = {operands + i, operands + i + 1, operands + i + 2, operands + i + 3};
    slice4(positions, four, leaves.data() + i, spheres);
  }
  if (i < leaves.size()) {
    const FourIndices tail = padded_tail(leaves, i);
    slice4(positions, padded_four(operands, i, leaves.size()).data(), tail.data(), spheres);
  }
}

void sliced_piece_spheres(const Vec3* positions, const SliceOperands* operands, std::span<const std::int32_t> leaves, Sphere* spheres) {
  if (cpu_has_avx2()) {
    sliced_piece_spheres_avx2(positions, operands, leaves, spheres);
  } else {
    sliced_piece_spheres_portable(positions, operands, leaves, spheres);
  }
}

void merge_children_portable(const ChildPair* children, std::span<const std::int32_t> nodes, Sphere* spheres) {
  for (std::size_t i = 0; i < nodes.size(); ++i) spheres[nodes[i]] = enclosing_sphere(spheres[children[i].left], spheres[children[i].right]);
}

namespace {

/// Four nodes' merges, lane by lane as enclosing_sphere() makes them.
__attribute__((target("avx2"), always_inline)) inline void merge4(const ChildPair* const* children, const std::int32_t* node, Sphere* spheres) {
  const ChildPair &l0 = *children[0], &l1 = *children[1], &l2 = *children[2], &l3 = *children[3];
  const Columns4 a = transpose4(load_sphere(spheres[l0.left]), load_sphere(spheres[l1.left]), load_sphere(spheres[l2.left]),
                                load_sphere(spheres[l3.left]));
  const Columns4 b = transpose4(load_sphere(spheres[l0.right]), load_sphere(spheres[l1.right]), load_sphere(spheres[l2.right]),
                                load_sphere(spheres[l3.right]));
  const __m256d ox = _mm256_sub_pd(b.x, a.x), oy = _mm256_sub_pd(b.y, a.y), oz = _mm256_sub_pd(b.z, a.z);
  const __m256d distance = _mm256_sqrt_pd(dot3(ox, oy, oz));
  // Where one sphere holds the other, that one, as it is; else the sphere over both, inflated.
  const __m256d a_holds_b = _mm256_cmp_pd(_mm256_add_pd(distance, b.w), a.w, _CMP_LE_OQ);
  const __m256d b_holds_a = _mm256_cmp_pd(_mm256_add_pd(distance, a.w), b.w, _CMP_LE_OQ);
  const __m256d radius = _mm256_mul_pd(_mm256_set1_pd(0.5), _mm256_add_pd(_mm256_add_pd(distance, a.w), b.w));
  const __m256d step = _mm256_div_pd(_mm256_sub_pd(radius, a.w), distance);
  const __m256d cx = _mm256_add_pd(a.x, _mm256_mul_pd(ox, step));
  const __m256d cy = _mm256_add_pd(a.y, _mm256_mul_pd(oy, step));
  const __m256d cz = _mm256_add_pd(a.z, _mm256_mul_pd(oz, step));
  const __m256d cr = inflated_radius(cx, cy, cz, radius);
  store_spheres(spheres, node,
                {pick(a_holds_b, b_holds_a, cx, a.x, b.x), pick(a_holds_b, b_holds_a, cy, a.y, b.y), pick(a_holds_b, b_holds_a, cz, a.z, b.z),
                 pick(a_holds_b, b_holds_a, cr, a.w, b.w)});
}

}  // namespace

__attribute__((target("avx2"))) void merge_children_avx2(const ChildPair* children, std::span<const std::int32_t> nodes, Sphere* spheres) {
  std::size_t i = 0;
  for (; i + 4 <= nodes.size(); i += 4) {
    const ChildPair* four[4] = {children + i, children + i + 1, children + i + 2, children + i + 3};
    merge4(four, nodes.data() + i, spheres);
  }
  if (i < nodes.size()) {
    const FourIndices tail = padded_tail(nodes, i);
    merge4(padded_four(children, i, nodes.size()).data(), tail.data(), spheres);
  }
}

void merge_children(const ChildPair* children, std::span<const std::int32_t> nodes, Sphere* spheres) {
  if (cpu_has_avx2()) {
    merge_children_avx2(children, nodes, spheres);
  } else {
    merge_children_portable(children, nodes, spheres);
  }
}

}  // namespace resecto
