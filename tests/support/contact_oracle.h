// The contact's candidate search against brute force (shared by the tissue and resection tests):
// every tissue surface node and every tool vertex within the margin of the other side, each with
// exactly the faces within the margin.
#pragma once

#include <gtest/gtest.h>

#include <map>
#include <set>
#include <span>
#include <utility>
#include <vector>

#include "rtcore/geometry/closest_point.h"
#include "rtcore/tissue/mass_spring.h"

namespace resecto::testing {

using Found = std::map<std::pair<int, std::uint32_t>, std::set<std::uint32_t>>;  // (part, point) -> faces

inline bool within(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c, double margin) {
  const Vec3 q = closest_point_on_triangle(p, a, b, c);
  return glm::dot(p - q, p - q) <= margin * margin;
}

/// Every surface node against every face of every part, and every part vertex against every live
/// surface face: the pairs within the margin, at the positions the search read. With `reach` and
/// `positions` (e.g. the nodes' current ones): the pairs within that reach there instead.
inline std::pair<Found, Found> brute_force(const MassSpringTissue& tissue, const std::vector<TriangleMesh>& parts, double reach = -1.0,
                                           std::span<const Vec3> positions = {}) {
  Found nodes, vertices;
  const TriangleMesh& surface = tissue.surface();
  const double margin = reach >= 0.0 ? reach : tissue.tool().margin_m();
  const std::span<const Vec3> x = positions.empty() ? std::span<const Vec3>(surface.positions) : positions;
  std::vector<std::uint8_t> on_surface(surface.vertex_count(), 0);
  std::vector<std::uint32_t> live_faces;
  for (std::uint32_t f = 0; f < surface.triangle_count(); ++f) {
    if (tissue.surface_face_owner(f) < 0) continue;
    live_faces.push_back(f);
    for (std::uint32_t n : surface.triangles[f]) on_surface[n] = 1;
  }
  for (int k = 0; k < static_cast<int>(parts.size()); ++k) {
    const TriangleMesh& mesh = parts[static_cast<std::size_t>(k)];
    const RigidPose& pose = tissue.tool().pose(k);
    for (std::uint32_t n = 0; n < surface.vertex_count(); ++n) {
      if (!on_surface[n]) continue;
      const Vec3 p = pose.inverse_apply_point(x[n]);
      for (std::uint32_t t = 0; t < mesh.triangle_count(); ++t) {
        const Triangle& tri = mesh.triangles[t];
        if (within(p, mesh.positions[tri[0]], mesh.positions[tri[1]], mesh.positions[tri[2]], margin)) nodes[{k, n}].insert(t);
      }
    }
    for (std::uint32_t v = 0; v < mesh.vertex_count(); ++v) {
      const Vec3 w = pose.apply_point(mesh.positions[v]);
      for (std::uint32_t f : live_faces) {
        const Triangle& tri = surface.triangles[f];
        if (within(w, x[tri[0]], x[tri[1]], x[tri[2]], margin)) vertices[{k, v}].insert(f);
      }
    }
  }
  return {nodes, vertices};
}

inline Found published(const ToolContacts& tool, bool tissue_nodes) {
  Found found;
  const std::size_t count = tissue_nodes ? tool.node_candidate_count() : tool.vertex_candidate_count();
  for (std::size_t i = 0; i < count; ++i) {
    const ToolContacts::CandidatePoint c = tissue_nodes ? tool.node_candidate(i) : tool.vertex_candidate(i);
    std::set<std::uint32_t>& faces = found[{c.part, c.point}];
    EXPECT_TRUE(faces.empty()) << "point " << c.point << " of part " << c.part << " listed twice";
    faces.insert(c.faces.begin(), c.faces.end());
    EXPECT_EQ(faces.size(), c.faces.size()) << "a face listed twice for point " << c.point;
  }
  return found;
}

inline void expect_brute_force(MassSpringTissue& tissue, const std::vector<TriangleMesh>& parts, const char* where) {
  tissue.collision_step();
  const auto [nodes, vertices] = brute_force(tissue, parts);
  const Found found_nodes = published(tissue.tool(), true), found_vertices = published(tissue.tool(), false);
  EXPECT_FALSE(tissue.tool().stats().overflowed) << where;
  EXPECT_EQ(found_nodes, nodes) << where << ": tissue nodes against the tool";
  EXPECT_EQ(found_vertices, vertices) << where << ": tool vertices against the tissue";
  EXPECT_GT(nodes.size() + vertices.size(), 0u) << where << ": the case should touch";
}

}  // namespace resecto::testing
