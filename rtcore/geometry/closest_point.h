// Closest points on triangles: the distance queries behind region labelling and penetration depth.
#pragma once

#include "rtcore/geometry/vec3.h"

namespace resecto {

/// The point of the closed triangle (a, b, c) closest to p (Ericson's region test, no division by
/// a zero area: degenerate triangles fall back to their edges).
Vec3 closest_point_on_triangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c);

}  // namespace resecto
