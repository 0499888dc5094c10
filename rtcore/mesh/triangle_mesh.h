// TriangleMesh: an indexed triangle surface in flat arrays, the shape every part of the core shares
// (anatomy generators write it, the loaders fill it, sphere trees and the tissue read it).
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include <glm/common.hpp>

#include "rtcore/base/result.h"
#include "rtcore/geometry/vec3.h"

namespace resecto {

using Triangle = std::array<std::uint32_t, 3>;

/// The largest coordinate magnitude a surface may have, in millimetres: 1 km, far beyond any gland
/// or tool. Past 1e154 squared lengths overflow to infinity (areas, sphere radii, grid cell counts),
/// so such coordinates would hang or exhaust the builders rather than mean anything; the readers
/// and validate_closed_surface() refuse them.
inline constexpr double kMaxSurfaceCoordinateMm = 1e6;

/// An indexed triangle mesh; positions in metres, triangles counter-clockwise seen from outside.
struct TriangleMesh {
  std::vector<Vec3> positions;
  std::vector<Triangle> triangles;
  /// For a mesh read from a file with polygons: per triangle, the file's face it is part of (fans keep
  /// file order), so messages name the face a person can find. Empty: triangle t is face t.
  std::vector<std::uint32_t> file_faces;

  std::size_t vertex_count() const { return positions.size(); }
  std::size_t triangle_count() const { return triangles.size(); }
};

/// Axis-aligned box.
struct Aabb {
  Vec3 min{0.0};
  Vec3 max{0.0};
  Vec3 size() const { return max - min; }
};

/// The box of a triangle's corners.
inline Aabb triangle_box(const Vec3& a, const Vec3& b, const Vec3& c) {
  return {glm::min(a, glm::min(b, c)), glm::max(a, glm::max(b, c))};
}
/// Whether two closed boxes share a point (touching counts): exact on the coordinates.
inline bool boxes_overlap(const Aabb& a, const Aabb& b) {
  return !(a.max.x < b.min.x || b.max.x < a.min.x || a.max.y < b.min.y || b.max.y < a.min.y || a.max.z < b.min.z ||
           b.max.z < a.min.z);
}

/// Area-weighted (unnormalised: twice the area) normal of triangle t.
Vec3 triangle_normal_x2(const TriangleMesh& mesh, std::size_t t);
double triangle_area(const TriangleMesh& mesh, std::size_t t);
double surface_area(const TriangleMesh& mesh);
/// Six times the signed volume of the tetrahedron from `from` to triangle (a, b, c), positive when the
/// triangle winds counter-clockwise seen from outside. Summed over a closed surface, six times its
/// volume from any point; from one near the surface, without the cancellation a far origin brings.
inline double six_volume_from(const Vec3& from, const Vec3& a, const Vec3& b, const Vec3& c) {
  return dot(a - from, cross(b - from, c - from));
}
/// Signed enclosed volume by the divergence theorem; positive for a closed, outward-oriented mesh.
double signed_volume(const TriangleMesh& mesh);
Aabb bounding_box(const TriangleMesh& mesh);
/// Appends `other` to `mesh`, offsetting its indices.
void append_mesh(TriangleMesh& mesh, const TriangleMesh& other);
/// The first vertex with a coordinate that is not finite or beyond ±kMaxSurfaceCoordinateMm, as an
/// error naming it; `mm_per_unit` says what the positions are in (1 for a file's millimetres, 1000
/// for metres).
Status check_coordinate_bound(const std::vector<Vec3>& positions, double mm_per_unit);
/// The mesh over only the vertices its triangles use, kept in their order (the triangles renumbered,
/// unchanged otherwise). A vertex no face uses is no part of the surface it sits in.
TriangleMesh without_unused_vertices(const TriangleMesh& mesh);

}  // namespace resecto
