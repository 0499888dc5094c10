// Closest points on triangles: the distance queries behind region labelling and penetration depth.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

#include "rtcore/geometry/vec3.h"

namespace resecto {

/// The point of the closed triangle (a, b, c) closest to p (Ericson's region test, no division by
/// a zero area: degenerate triangles fall back to their edges).
Vec3 closest_point_on_triangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c);

/// d2[k] = the squared distance from p to triangle faces[k] (corner indices into `positions`), for
/// k < count: exactly length_squared(p - closest_point_on_triangle(...)), the same bits on both
/// paths. The contact search measures every candidate pair this way, so four go at once.
void squared_distances_to_triangles(const Vec3& p, const Vec3* positions, const std::array<std::uint32_t, 3>* triangles,
                                    const std::uint32_t* faces, std::size_t count, double* d2);
void squared_distances_to_triangles_portable(const Vec3& p, const Vec3* positions, const std::array<std::uint32_t, 3>* triangles,
                                             const std::uint32_t* faces, std::size_t count, double* d2);
/// The same four triangles per instruction; call only where cpu_has_avx2().
void squared_distances_to_triangles_avx2(const Vec3& p, const Vec3* positions, const std::array<std::uint32_t, 3>* triangles,
                                         const std::uint32_t* faces, std::size_t count, double* d2);

}  // namespace resecto
