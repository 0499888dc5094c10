// The core's vector type. GLM's double-precision vectors: header-only, IEEE arithmetic with no
// reassociation, so results are reproducible under the root build's floating-point rules.
#pragma once

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

namespace resecto {

using Vec3 = glm::dvec3;

inline double dot(const Vec3& a, const Vec3& b) { return glm::dot(a, b); }
inline Vec3 cross(const Vec3& a, const Vec3& b) { return glm::cross(a, b); }
inline double length(const Vec3& a) { return glm::length(a); }
inline double length_squared(const Vec3& a) { return glm::dot(a, a); }

/// A distance formed by rounded subtractions and square roots (or a sum of such), pushed up past
/// their rounding by a relative part and a femtometre: the contact's certificates and bounds need a
/// figure never below the true one.
inline double rounded_up(double distance_m) { return distance_m * (1.0 + 1e-9) + 1e-15; }

}  // namespace resecto
