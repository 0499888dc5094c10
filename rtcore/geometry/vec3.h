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

}  // namespace resecto
