// The refit's arithmetic: a leaf's sphere from its triangle's corners, and an internal node's sphere
// from its children's, one at a time and four at a time (AVX2). A refit is a full pass over the tree
// after every deformation, and its square roots and divisions are what it waits on: four lanes
// issue four of them at once. Each AVX2 loop mirrors the one-at-a-time functions operation for
// operation, so both give the same bits (tests/rtcore/collision/sphere_refit_kernel_test.cpp).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <span>

#include "rtcore/base/cpu_features.h"
#include "rtcore/collision/sphere_tree.h"

namespace resecto {

/// A sphere whose radius is grown by far more than the few ulps of rounding in its centre and
/// radius (relative, plus a floor tied to the coordinates' magnitude), so the cover is conservative.
inline Sphere inflated_sphere(const Vec3& center, double radius) {
  const double magnitude = std::max({std::abs(center.x), std::abs(center.y), std::abs(center.z), radius});
  return {center, radius * (1.0 + 1e-12) + magnitude * 1e-15};
}

/// The smallest sphere holding both spheres.
inline Sphere enclosing_sphere(const Sphere& a, const Sphere& b) {
  const Vec3 offset = b.center - a.center;
  const double distance = length(offset);
  if (distance + b.radius <= a.radius) return a;
  if (distance + a.radius <= b.radius) return b;
  const double radius = 0.5 * (distance + a.radius + b.radius);
  return inflated_sphere(a.center + offset * ((radius - a.radius) / distance), radius);
}

/// The sphere about a triangle's centroid through its furthest corner: not the smallest, but three
/// squared distances and one square root, which is what a refit of every leaf can afford.
inline Sphere centroid_sphere(const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 center = (a + b + c) * (1.0 / 3.0);
  const double r2 = std::max({length_squared(a - center), length_squared(b - center), length_squared(c - center)});
  return inflated_sphere(center, std::sqrt(r2));
}

/// spheres[leaves[i]] = the centroid sphere of triangle corners[i], for every leaf of `leaves` (each a
/// whole-triangle piece: LeafPiece::slices == 1), its triangle's corners read from an array in the
/// leaves' order rather than through the piece and the mesh's triangles: two dependent loads fewer a
/// leaf. Finite corners give the same bits on both paths.
void centroid_spheres(const Vec3* positions, const Triangle* corners, std::span<const std::int32_t> leaves, Sphere* spheres);
void centroid_spheres_portable(const Vec3* positions, const Triangle* corners, std::span<const std::int32_t> leaves, Sphere* spheres);
/// The same four leaves per instruction; call only where cpu_has_avx2().
void centroid_spheres_avx2(const Vec3* positions, const Triangle* corners, std::span<const std::int32_t> leaves, Sphere* spheres);

/// spheres[leaves[i]] = SphereTree::slice_sphere of operands[i], for every leaf of `leaves` (each a
/// slice of a long thin triangle: LeafPiece::slices > 1), its operands in the leaves' order. Finite
/// corners give the same bits on both paths.
void sliced_piece_spheres(const Vec3* positions, const SliceOperands* operands, std::span<const std::int32_t> leaves, Sphere* spheres);
void sliced_piece_spheres_portable(const Vec3* positions, const SliceOperands* operands, std::span<const std::int32_t> leaves, Sphere* spheres);
/// The same four leaves per instruction; call only where cpu_has_avx2().
void sliced_piece_spheres_avx2(const Vec3* positions, const SliceOperands* operands, std::span<const std::int32_t> leaves, Sphere* spheres);

/// spheres[nodes[i]] = the enclosing sphere of children[i]'s two spheres, for every internal node of
/// `nodes`, none of which may be a child of another (one height's nodes, say): the AVX2 path merges
/// four at once. The children come in the nodes' order, not through the links: one load chain fewer.
void merge_children(const ChildPair* children, std::span<const std::int32_t> nodes, Sphere* spheres);
void merge_children_portable(const ChildPair* children, std::span<const std::int32_t> nodes, Sphere* spheres);
/// The same four nodes per instruction; call only where cpu_has_avx2().
void merge_children_avx2(const ChildPair* children, std::span<const std::int32_t> nodes, Sphere* spheres);

}  // namespace resecto
