// Measures of an indexed triangle mesh.
#include "rtcore/mesh/triangle_mesh.h"

#include <algorithm>

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
  double six_volume = 0.0;
  for (const Triangle& tri : mesh.triangles) {
    const Vec3& a = mesh.positions[tri[0]];
    six_volume += dot(a, cross(mesh.positions[tri[1]], mesh.positions[tri[2]]));
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

}  // namespace resecto
