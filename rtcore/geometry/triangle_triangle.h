// Exact orientation predicates and the closed triangle-triangle intersection test (Guigue-Devillers)
// built on them. Mesh validation and the collision query both ask "do these two triangles touch?".
#pragma once

#include "rtcore/geometry/vec3.h"

namespace resecto {

/// Sign (-1, 0, +1) of dot(d - a, cross(b - a, c - a)): +1 when d lies on the side the normal of
/// the counter-clockwise triangle (a, b, c) points to. Exact: a floating-point filter, then exact
/// expansion arithmetic when the filter cannot decide.
int orient3d(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d);

/// Sign (-1, 0, +1) of the 2D determinant of (b - a, c - a) for points given as (x, y); exact.
int orient2d(double ax, double ay, double bx, double by, double cx, double cy);

/// True when the closed segment [s, t] and the closed triangle (a, b, c) share a point; exact.
/// The triangle must have nonzero area; the segment may be a point.
bool segment_intersects_triangle(const Vec3& s, const Vec3& t, const Vec3& a, const Vec3& b,
                                 const Vec3& c);

/// True when the closed triangles (p0, p1, p2) and (q0, q1, q2) share at least one point:
/// crossing, coplanar overlap, a shared edge or vertex, or mere touching all count. Decided
/// exactly on the double inputs. A zero-area triangle counts as the segment it spans when the
/// other has area; two zero-area triangles never report an intersection.
bool triangles_intersect(const Vec3& p0, const Vec3& p1, const Vec3& p2, const Vec3& q0,
                         const Vec3& q1, const Vec3& q2);

}  // namespace resecto
