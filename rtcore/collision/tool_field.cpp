#include "rtcore/collision/tool_field.h"

#include <algorithm>
#include <cmath>

namespace resecto {

void ToolField::build(const TriangleMesh& mesh) {
  // Cells grow with the tool's triangles, up to about a million (the resectoscope's 488 reach it): a
  // small tool, whose few triangles each cross many cells, gets a small field built in milliseconds.
  const std::size_t triangles = mesh.triangle_count();
  const std::size_t cells = std::clamp<std::size_t>(8 * triangles * triangles, 4096, std::size_t{1} << 20);
  clearance_.build(mesh, cells);
  planes_.resize(mesh.triangle_count());
  for (std::uint32_t t = 0; t < mesh.triangle_count(); ++t) {
    const Vec3& a = mesh.positions[mesh.triangles[t][0]];
    const Vec3& b = mesh.positions[mesh.triangles[t][1]];
    const Vec3& c = mesh.positions[mesh.triangles[t][2]];
    const Vec3 n = cross(b - a, c - a);
    const double n_length = length(n);
    ToolPlane& plane = planes_[t];
    plane.normal = n_length > 0.0 ? n / n_length : Vec3(0.0);
    plane.offset = dot(plane.normal, a);
    // However rough the computed normal of a sliver, the thickness measured from it bounds the
    // triangle: every point is an affine mix of the corners.
    double spread = 0.0, magnitude = 0.0;
    for (const Vec3* v : {&a, &b, &c}) {
      spread = std::max(spread, std::abs(dot(plane.normal, *v) - plane.offset));
      magnitude = std::max({magnitude, std::abs(v->x), std::abs(v->y), std::abs(v->z)});
    }
    plane.thickness = spread + 1e-12 * magnitude;
    plane.box = triangle_box(a, b, c);
  }
  // Reaches of 1, 2, 4, 8 and 16 clearance cells: a leaf takes the smallest that holds its sphere, so
  // its list is not much longer than what is truly near it.
  double reach = clearance_.cell_m();
  for (std::size_t k = 0; k < kReaches; ++k, reach *= 2.0) {
    // The small reaches get fine cells too, or their lists would be the cells' size, not theirs.
    near_[k].build(mesh, reach, k < 2 ? cells : cells / 4);
    usable_reach_[k] = mesh.triangle_count() == 0 ? -1.0 : reach * (1.0 - 1e-6);
  }
}

}  // namespace resecto
