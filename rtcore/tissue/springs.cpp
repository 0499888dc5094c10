// Spring network construction: unique edges by sorted key, volume shares, capsule anchors.
#include "rtcore/tissue/springs.h"

#include <algorithm>
#include <array>
#include <cmath>

#include "rtcore/geometry/vec3.h"

namespace resecto {

SpringNetwork build_spring_network(const TetMesh& mesh) {
  SpringNetwork net;
  const std::size_t node_count = mesh.node_count();
  net.node_volume_m3.assign(node_count, 0.0);

  struct Edge {
    std::uint64_t key;  // smaller node << 32 | larger node
    double volume_share;
  };
  std::vector<Edge> edges;
  edges.reserve(6 * mesh.tetrahedron_count());
  constexpr std::array<std::array<int, 2>, 6> kTetEdges = {{{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}}};
  for (std::size_t t = 0; t < mesh.tetrahedron_count(); ++t) {
    const Tetrahedron& tet = mesh.tetrahedra[t];
    const double volume = std::abs(tetrahedron_volume(mesh, t));
    for (std::uint32_t n : tet) net.node_volume_m3[n] += 0.25 * volume;
    for (const auto& e : kTetEdges) {
      const std::uint64_t a = std::min(tet[e[0]], tet[e[1]]), b = std::max(tet[e[0]], tet[e[1]]);
      edges.push_back({a << 32 | b, volume / 6.0});
    }
  }
  // Stable sort on the key, then summing runs in tetrahedron order: the same sums every run.
  std::stable_sort(edges.begin(), edges.end(), [](const Edge& x, const Edge& y) { return x.key < y.key; });
  for (std::size_t i = 0; i < edges.size();) {
    double share = 0.0;
    std::size_t j = i;
    for (; j < edges.size() && edges[j].key == edges[i].key; ++j) share += edges[j].volume_share;
    const auto a = static_cast<std::uint32_t>(edges[i].key >> 32), b = static_cast<std::uint32_t>(edges[i].key & 0xffffffffu);
    net.spring_nodes.push_back(a);
    net.spring_nodes.push_back(b);
    net.rest_length_m.push_back(glm::length(mesh.positions[b] - mesh.positions[a]));
    net.volume_share_m3.push_back(share);
    i = j;
  }

  // Anchors: boundary nodes of capsule tetrahedra.
  std::vector<std::uint8_t> touches_capsule(node_count, 0);
  for (std::size_t t = 0; t < mesh.tetrahedron_count(); ++t) {
    if (mesh.regions[t] == TissueRegion::kCapsule) {
      for (std::uint32_t n : mesh.tetrahedra[t]) touches_capsule[n] = 1;
    }
  }
  const TriangleMesh surface = boundary_surface(mesh);
  std::vector<double> area(node_count, 0.0);
  std::vector<std::uint8_t> on_boundary(node_count, 0);
  for (std::size_t f = 0; f < surface.triangle_count(); ++f) {
    const double third = triangle_area(surface, f) / 3.0;
    for (std::uint32_t n : surface.triangles[f]) {
      area[n] += third;
      on_boundary[n] = 1;
    }
  }
  for (std::uint32_t n = 0; n < node_count; ++n) {
    if (on_boundary[n] && touches_capsule[n]) {
      net.anchor_nodes.push_back(n);
      net.anchor_area_m2.push_back(area[n]);
    }
  }
  return net;
}

}  // namespace resecto
