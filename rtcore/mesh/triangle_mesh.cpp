// Measures of an indexed triangle mesh.
#include "rtcore/mesh/triangle_mesh.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdint>

namespace resecto {

Vec3 triangle_normal_x2(const TriangleMesh& mesh, std::size_t t) {
  const Triangle& tri = mesh.triangles[t];
  const Vec3& a = mesh.positions[tri[0]];
  return cross(mesh.positions[tri[1]] - a, mesh.positions[tri[2]] - a);
}

double triangle_area(const TriangleMesh& mesh, std::size_t t) {
  return 0.5 * length(triangle_normal_x2(mesh, t));
}

double surface_area(const TriangleMesh& mesh) {
  double area = 0.0;
  // Summed in triangle order, so the total is the same on every run.
  for (std::size_t t = 0; t < mesh.triangle_count(); ++t) area += triangle_area(mesh, t);
  return area;
}

double signed_volume(const TriangleMesh& mesh) {
  // Tetrahedra from a point at the mesh's box centre: about the world origin the terms of a small
  // solid far from it (a part in scanner coordinates, 1e6 mm out) cancel to noise, and a correct 1 mm
  // cube read as inward. A closed surface's volume is the same from any point.
  const Aabb box = bounding_box(mesh);
  const Vec3 centre = 0.5 * (box.min + box.max);
  double six_volume = 0.0;
  for (const Triangle& tri : mesh.triangles) {
    six_volume += six_volume_from(centre, mesh.positions[tri[0]], mesh.positions[tri[1]], mesh.positions[tri[2]]);
  }
  return six_volume / 6.0;
}

Aabb bounding_box(const TriangleMesh& mesh) {
  if (mesh.positions.empty()) return {};
  Aabb box{mesh.positions[0], mesh.positions[0]};
  for (const Vec3& p : mesh.positions) {
    box.min = glm::min(box.min, p);
    box.max = glm::max(box.max, p);
  }
  return box;
}

void append_mesh(TriangleMesh& mesh, const TriangleMesh& other) {
  const auto offset = static_cast<std::uint32_t>(mesh.positions.size());
  mesh.positions.insert(mesh.positions.end(), other.positions.begin(), other.positions.end());
  for (const Triangle& tri : other.triangles) {
    mesh.triangles.push_back({tri[0] + offset, tri[1] + offset, tri[2] + offset});
  }
}

Status check_coordinate_bound(const std::vector<Vec3>& positions, double mm_per_unit) {
  for (std::size_t v = 0; v < positions.size(); ++v) {
    for (int a = 0; a < 3; ++a) {
      const double mm = positions[v][a] * mm_per_unit;
      if (std::abs(mm) <= kMaxSurfaceCoordinateMm) continue;  // false for NaN too
      char what[128];
      std::snprintf(what, sizeof what, "vertex %zu has coordinate %g mm, beyond the ±%g mm a surface may reach", v, mm,
                    kMaxSurfaceCoordinateMm);
      return Error{what};
    }
  }
  return Ok{};
}

TriangleMesh without_unused_vertices(const TriangleMesh& mesh) {
  constexpr std::uint32_t kUnused = UINT32_MAX;
  std::vector<std::uint32_t> renumbered(mesh.vertex_count(), kUnused);
  for (const Triangle& tri : mesh.triangles) {
    for (std::uint32_t v : tri) renumbered[v] = 0;
  }
  TriangleMesh compact;
  // Kept in input order, so the mesh with every vertex used comes back unchanged.
  for (std::size_t v = 0; v < mesh.vertex_count(); ++v) {
    if (renumbered[v] == kUnused) continue;
    renumbered[v] = static_cast<std::uint32_t>(compact.positions.size());
    compact.positions.push_back(mesh.positions[v]);
  }
  compact.triangles.reserve(mesh.triangle_count());
  for (const Triangle& tri : mesh.triangles) compact.triangles.push_back({renumbered[tri[0]], renumbered[tri[1]], renumbered[tri[2]]});
  return compact;
}

}  // namespace resecto
