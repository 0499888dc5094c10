// Closed-surface validation. Checks run cheapest first and stop at the first defect, so the message
// names the first offending face or vertex in file order.
#include "rtcore/mesh/mesh_validation.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <map>
#include <numbers>
#include <numeric>
#include <span>
#include <string>
#include <tuple>
#include <vector>

#include <glm/common.hpp>
#include <glm/vector_relational.hpp>

#include "rtcore/base/units.h"
#include "rtcore/geometry/triangle_triangle.h"

namespace resecto {
namespace {

// The face as the file numbers it: a polygon's triangles (fan order) name their polygon too.
std::string face_name(const TriangleMesh& mesh, std::size_t f) {
  if (mesh.file_faces.size() != mesh.triangle_count()) return "face " + std::to_string(f);
  return "face " + std::to_string(mesh.file_faces[f]) + " (its fan triangle " + std::to_string(f) + ")";
}
std::string vertex_name(std::size_t v) { return "vertex " + std::to_string(v); }
// Where a vertex is, in the file's millimetres: an STL file numbers no vertices (its corners are
// numbered in order of first appearance), so a number alone would not find the place in it.
std::string millimetres(const Vec3& p) {
  char text[96];
  std::snprintf(text, sizeof text, "(%.6g, %.6g, %.6g)", units::m_to_mm(p.x), units::m_to_mm(p.y), units::m_to_mm(p.z));
  return text;
}
std::string located_vertex(const TriangleMesh& mesh, std::size_t v) { return vertex_name(v) + " at " + millimetres(mesh.positions[v]) + " mm"; }
std::string edge_place(const TriangleMesh& mesh, std::uint32_t a, std::uint32_t b) {
  return "; the edge runs from " + millimetres(mesh.positions[a]) + " to " + millimetres(mesh.positions[b]) + " mm";
}

/// One undirected edge occurrence: its endpoints sorted, the face it came from and whether the
/// face walks it from low to high index.
struct EdgeUse {
  std::uint32_t low;
  std::uint32_t high;
  std::uint32_t face;
  bool forward;
};

class DisjointSets {
 public:
  explicit DisjointSets(std::size_t n) : parent_(n) { std::iota(parent_.begin(), parent_.end(), 0u); }
  std::uint32_t find(std::uint32_t x) {
    while (parent_[x] != x) x = parent_[x] = parent_[parent_[x]];
    return x;
  }
  void unite(std::uint32_t a, std::uint32_t b) {
    a = find(a);
    b = find(b);
    if (a != b) parent_[std::max(a, b)] = std::min(a, b);  // smaller index wins: order-independent roots
  }

 private:
  std::vector<std::uint32_t> parent_;
};

std::string mm2(double m2) {
  char text[64];
  std::snprintf(text, sizeof text, "%.3g mm^2", m2 * 1e6);
  return text;
}

Status check_faces(const TriangleMesh& mesh, const ValidationOptions& options) {
  const std::size_t vertex_count = mesh.vertex_count();
  for (std::size_t f = 0; f < mesh.triangle_count(); ++f) {
    const Triangle& t = mesh.triangles[f];
    for (std::uint32_t v : t) {
      if (v >= vertex_count) return Error{face_name(mesh, f) + " refers to missing " + vertex_name(v)};
    }
    if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2]) {
      return Error{"degenerate triangle: " + face_name(mesh, f) + " uses a vertex twice"};
    }
  }
  if (Status bounded = check_coordinate_bound(mesh.positions, units::kMillimetresPerMetre); !bounded) return bounded;
  const double mean_area = surface_area(mesh) / static_cast<double>(std::max<std::size_t>(1, mesh.triangle_count()));
  const double threshold = options.degenerate_area_fraction * mean_area;
  for (std::size_t f = 0; f < mesh.triangle_count(); ++f) {
    const double area = triangle_area(mesh, f);
    if (!(area > threshold)) {
      return Error{"degenerate triangle: " + face_name(mesh, f) + " has area " + mm2(area) + " (mean " + mm2(mean_area) + ")"};
    }
  }
  return Ok{};
}

/// How many vertices stand exactly where an earlier one does (a "triangle soup": every face with its
/// own corners, as some exporters write OFF, OBJ and PLY). Only on the error path: a sort.
std::size_t coincident_vertices(const TriangleMesh& mesh) {
  std::vector<std::array<double, 3>> points;
  points.reserve(mesh.vertex_count());
  for (const Vec3& p : mesh.positions) points.push_back({p.x, p.y, p.z});
  std::sort(points.begin(), points.end());
  std::size_t repeats = 0;
  for (std::size_t i = 1; i < points.size(); ++i) repeats += points[i] == points[i - 1] ? 1 : 0;
  return repeats;
}

/// Every undirected edge must be used by exactly two faces walking it in opposite directions.
Status check_edges(const TriangleMesh& mesh, std::vector<EdgeUse>& uses) {
  uses.clear();
  uses.reserve(3 * mesh.triangle_count());
  for (std::size_t f = 0; f < mesh.triangle_count(); ++f) {
    const Triangle& t = mesh.triangles[f];
    for (int c = 0; c < 3; ++c) {
      const std::uint32_t a = t[c], b = t[(c + 1) % 3];
      uses.push_back({std::min(a, b), std::max(a, b), static_cast<std::uint32_t>(f), a < b});
    }
  }
  // Sorted by edge then face: ties are impossible, so the order (and the first error) is fixed.
  std::sort(uses.begin(), uses.end(), [](const EdgeUse& x, const EdgeUse& y) {
    return std::tie(x.low, x.high, x.face) < std::tie(y.low, y.high, y.face);
  });
  // Report the defect whose first face comes earliest in the file.
  std::string error;
  std::uint32_t error_face = UINT32_MAX;
  for (std::size_t i = 0; i < uses.size();) {
    std::size_t j = i;
    while (j < uses.size() && uses[j].low == uses[i].low && uses[j].high == uses[i].high) ++j;
    const std::size_t count = j - i;
    const std::string edge = "edge (" + std::to_string(uses[i].low) + ", " + std::to_string(uses[i].high) + ")";
    std::string problem;
    if (count == 1) {
      problem = "open surface: " + edge + " of " + face_name(mesh, uses[i].face) + " has no neighbouring face";
    } else if (count > 2) {
      problem = "non-manifold " + edge + " is shared by " + std::to_string(count) + " faces (" + face_name(mesh, uses[i].face);
      for (std::size_t k = i + 1; k < std::min(j, i + 6); ++k) problem += ", " + std::to_string(uses[k].face);
      problem += count > 6 ? ", ...)" : ")";
    } else if (uses[i].forward == uses[i + 1].forward) {
      problem = "inconsistent orientation: " + face_name(mesh, uses[i].face) + " and " + face_name(mesh, uses[i + 1].face) +
                " walk " + edge + " the same way";
    }
    if (!problem.empty() && uses[i].face < error_face) {
      error_face = uses[i].face;
      error = problem + edge_place(mesh, uses[i].low, uses[i].high);
    }
    i = j;
  }
  if (!error.empty()) {
    if (const std::size_t repeats = coincident_vertices(mesh); repeats > 0 && error.starts_with("open surface")) {
      error += "; " + std::to_string(repeats) + " vertices repeat the coordinates of another, so faces that meet there are not joined " +
               "(a triangle soup): merge coincident vertices (MeshLab: Remove Duplicate Vertices) or save it as STL, whose corners resecto merges";
    }
    return Error{error};
  }
  return Ok{};
}

/// A vertex whose faces form more than one fan (two cones touching at a point) is non-manifold even
/// when every edge is. Walks each vertex's fan across shared edges and counts the faces reached.
Status check_vertex_fans(const TriangleMesh& mesh) {
  const std::size_t n = mesh.vertex_count();
  std::vector<std::uint32_t> first(n + 1, 0);
  for (const Triangle& t : mesh.triangles) {
    for (std::uint32_t v : t) ++first[v + 1];
  }
  std::partial_sum(first.begin(), first.end(), first.begin());
  std::vector<std::uint32_t> incident(first[n]);
  std::vector<std::uint32_t> fill(first.begin(), first.end() - 1);
  for (std::size_t f = 0; f < mesh.triangle_count(); ++f) {
    for (std::uint32_t v : mesh.triangles[f]) incident[fill[v]++] = static_cast<std::uint32_t>(f);
  }
  std::vector<char> reached;
  for (std::size_t v = 0; v < n; ++v) {
    const std::uint32_t begin = first[v], end = first[v + 1];
    if (begin == end) continue;
    const std::uint32_t count = end - begin;
    reached.assign(count, 0);
    // Flood over faces around v that share a second vertex (an edge through v).
    std::vector<std::uint32_t> stack{0};
    reached[0] = 1;
    std::uint32_t seen = 1;
    while (!stack.empty()) {
      const std::uint32_t a = stack.back();
      stack.pop_back();
      const Triangle& ta = mesh.triangles[incident[begin + a]];
      for (std::uint32_t b = 0; b < count; ++b) {
        if (reached[b]) continue;
        const Triangle& tb = mesh.triangles[incident[begin + b]];
        int shared = 0;
        for (std::uint32_t x : ta) shared += (x == tb[0] || x == tb[1] || x == tb[2]) ? 1 : 0;
        if (shared >= 2) {
          reached[b] = 1;
          ++seen;
          stack.push_back(b);
        }
      }
    }
    if (seen != count) {
      return Error{"non-manifold " + located_vertex(mesh, v) + ": its faces form separate fans (faces " +
                   std::to_string(incident[begin]) + " and others meet only at this vertex)"};
    }
  }
  return Ok{};
}

int count_shared_vertices(const Triangle& a, const Triangle& b) {
  int shared = 0;
  for (std::uint32_t x : a) shared += (x == b[0] || x == b[1] || x == b[2]) ? 1 : 0;
  return shared;
}

/// Do two faces of the mesh cross? Neighbours touch by construction, so for faces sharing a vertex
/// only the edges away from it may not meet the other face; faces sharing an edge are left to the
/// orientation check.
bool faces_cross(const TriangleMesh& mesh, std::uint32_t f, std::uint32_t g) {
  const Triangle& a = mesh.triangles[f];
  const Triangle& b = mesh.triangles[g];
  const auto& p = mesh.positions;
  const int shared = count_shared_vertices(a, b);
  if (shared == 0) return triangles_intersect(p[a[0]], p[a[1]], p[a[2]], p[b[0]], p[b[1]], p[b[2]]);
  if (shared >= 2) return false;
  auto opposite_edge_hits = [&](const Triangle& t, const Triangle& other) {
    for (int c = 0; c < 3; ++c) {
      const bool is_shared = t[c] == other[0] || t[c] == other[1] || t[c] == other[2];
      if (is_shared) {
        return segment_intersects_triangle(p[t[(c + 1) % 3]], p[t[(c + 2) % 3]], p[other[0]], p[other[1]], p[other[2]]);
      }
    }
    return false;
  };
  return opposite_edge_hits(a, b) || opposite_edge_hits(b, a);
}

/// Sweep along x over face bounding boxes; candidates whose boxes overlap are tested exactly.
Status check_self_intersections(const TriangleMesh& mesh) {
  const std::size_t n = mesh.triangle_count();
  std::vector<Aabb> boxes(n);
  for (std::size_t f = 0; f < n; ++f) {
    const Triangle& t = mesh.triangles[f];
    boxes[f].min = glm::min(glm::min(mesh.positions[t[0]], mesh.positions[t[1]]), mesh.positions[t[2]]);
    boxes[f].max = glm::max(glm::max(mesh.positions[t[0]], mesh.positions[t[1]]), mesh.positions[t[2]]);
  }
  std::vector<std::uint32_t> order(n);
  std::iota(order.begin(), order.end(), 0u);
  std::stable_sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) { return boxes[a].min.x < boxes[b].min.x; });
  std::pair<std::uint32_t, std::uint32_t> first_hit{UINT32_MAX, UINT32_MAX};
  for (std::size_t i = 0; i < n; ++i) {
    const Aabb& bi = boxes[order[i]];
    for (std::size_t j = i + 1; j < n && boxes[order[j]].min.x <= bi.max.x; ++j) {
      const Aabb& bj = boxes[order[j]];
      if (bj.min.y > bi.max.y || bj.max.y < bi.min.y || bj.min.z > bi.max.z || bj.max.z < bi.min.z) continue;
      std::uint32_t f = order[i], g = order[j];
      if (f > g) std::swap(f, g);
      if (std::make_pair(f, g) < first_hit && faces_cross(mesh, f, g)) first_hit = {f, g};
    }
  }
  if (first_hit.first != UINT32_MAX) {
    const bool one_polygon = mesh.file_faces.size() == mesh.triangle_count() &&
                             mesh.file_faces[first_hit.first] == mesh.file_faces[first_hit.second];
    if (one_polygon) {
      return Error{"self-intersection inside face " + std::to_string(mesh.file_faces[first_hit.first]) +
                   ": its fan triangulation (around its first corner) crosses itself, fan triangles " + std::to_string(first_hit.first) +
                   " and " + std::to_string(first_hit.second) + "; the polygon is not convex from that corner: split it into triangles"};
    }
    return Error{"self-intersection: " + face_name(mesh, first_hit.first) + " crosses " + face_name(mesh, first_hit.second)};
  }
  return Ok{};
}

/// The winding number of the closed surface made of `faces` around p: 1 inside an outward shell,
/// 0 outside (the sum of the faces' solid angles over 4 pi, Van Oosterom and Strackee's formula).
double winding_number(const TriangleMesh& mesh, std::span<const std::uint32_t> faces, const Vec3& p) {
  double solid_angle = 0.0;
  for (const std::uint32_t f : faces) {
    const Triangle& t = mesh.triangles[f];
    const Vec3 a = mesh.positions[t[0]] - p, b = mesh.positions[t[1]] - p, c = mesh.positions[t[2]] - p;
    const double la = length(a), lb = length(b), lc = length(c);
    const double numerator = dot(a, cross(b, c));
    const double denominator = la * lb * lc + dot(a, b) * lc + dot(b, c) * la + dot(c, a) * lb;
    solid_angle += 2.0 * std::atan2(numerator, denominator);
  }
  return solid_angle / (4.0 * std::numbers::pi);
}

/// Several closed shells are several solids side by side; one inside another would be read as two
/// solids overlapping (its volume counted twice, and lost when tetrahedralized), and a cavity,
/// wound inward, is refused with the orientation. So no shell may lie inside another.
Status check_no_nested_shells(const TriangleMesh& mesh, DisjointSets& components, const std::vector<std::uint32_t>& component_first_face) {
  struct Shell {
    std::vector<std::uint32_t> faces;
    Vec3 low{1e300}, high{-1e300};
  };
  std::map<std::uint32_t, Shell> shells;  // by component root, in order: the same report every run
  for (std::uint32_t f = 0; f < mesh.triangle_count(); ++f) {
    Shell& shell = shells[components.find(mesh.triangles[f][0])];
    shell.faces.push_back(f);
    for (const std::uint32_t v : mesh.triangles[f]) {
      shell.low = glm::min(shell.low, mesh.positions[v]);
      shell.high = glm::max(shell.high, mesh.positions[v]);
    }
  }
  for (const auto& [inner_root, inner] : shells) {
    // The shells do not intersect (checked before), so one vertex tells where the whole shell is;
    // only a shell whose box holds it can hold it (many small shells then cost little).
    const Vec3& probe = mesh.positions[mesh.triangles[inner.faces.front()][0]];
    for (const auto& [outer_root, outer] : shells) {
      if (outer_root == inner_root || glm::any(glm::lessThan(probe, outer.low)) || glm::any(glm::greaterThan(probe, outer.high))) continue;
      if (winding_number(mesh, outer.faces, probe) < 0.5) continue;
      return Error{"nested shells: the component containing " + face_name(mesh, component_first_face[inner_root]) + " lies inside the component containing " +
                   face_name(mesh, component_first_face[outer_root]) + "; a solid with a cavity is not read (each component must be a solid of its own, outside the others)"};
    }
  }
  return Ok{};
}

}  // namespace

Result<SurfaceReport> validate_closed_surface(const TriangleMesh& mesh, const ValidationOptions& options) {
  if (mesh.triangles.empty()) return Error{"the mesh has no faces"};
  if (Status s = check_faces(mesh, options); !s) return Error{s.error()};
  std::vector<EdgeUse> uses;
  if (Status s = check_edges(mesh, uses); !s) return Error{s.error()};
  if (Status s = check_vertex_fans(mesh); !s) return Error{s.error()};

  SurfaceReport report;
  report.triangles = mesh.triangle_count();
  report.edges = uses.size() / 2;
  DisjointSets components(mesh.vertex_count());
  std::vector<char> used(mesh.vertex_count(), 0);
  for (const Triangle& t : mesh.triangles) {
    for (std::uint32_t v : t) used[v] = 1;
    components.unite(t[0], t[1]);
    components.unite(t[1], t[2]);
  }
  for (std::size_t v = 0; v < mesh.vertex_count(); ++v) {
    if (!used[v]) {
      ++report.unused_vertices;
      continue;
    }
    ++report.vertices;
    if (components.find(static_cast<std::uint32_t>(v)) == v) ++report.components;
  }
  report.euler_characteristic = static_cast<int>(report.vertices) - static_cast<int>(report.edges) + static_cast<int>(report.triangles);
  report.genus = (2 * report.components - report.euler_characteristic) / 2;
  report.area_m2 = surface_area(mesh);
  report.volume_m3 = signed_volume(mesh);

  // Orientation is checked per component: each must enclose positive volume.
  // Each from a corner of the component's first face, not the world origin (signed_volume's reason).
  std::vector<double> component_volume(mesh.vertex_count(), 0.0);
  std::vector<std::uint32_t> component_first_face(mesh.vertex_count(), UINT32_MAX);
  for (std::size_t f = 0; f < mesh.triangle_count(); ++f) {
    const Triangle& t = mesh.triangles[f];
    const std::uint32_t root = components.find(t[0]);
    component_first_face[root] = std::min(component_first_face[root], static_cast<std::uint32_t>(f));
    const Vec3& from = mesh.positions[mesh.triangles[component_first_face[root]][0]];
    component_volume[root] += six_volume_from(from, mesh.positions[t[0]], mesh.positions[t[1]], mesh.positions[t[2]]) / 6.0;
  }
  for (std::size_t v = 0; v < mesh.vertex_count(); ++v) {
    if (component_first_face[v] != UINT32_MAX && component_volume[v] <= 0.0) {
      // A rightly wound cavity encloses negative volume too, and was told to turn its faces (audit 32,
      // F14): a shell inside another is named as the cavity it is.
      if (report.components > 1) {
        if (Status nested = check_no_nested_shells(mesh, components, component_first_face); !nested) return Error{nested.error()};
      }
      return Error{"inward orientation: the component containing " + face_name(mesh, component_first_face[v]) +
                   " encloses negative volume; faces must wind counter-clockwise seen from outside"};
    }
  }

  report.min_edge_m = 1e300;
  report.min_angle_deg = 180.0;
  for (std::size_t f = 0; f < mesh.triangle_count(); ++f) {
    const Triangle& t = mesh.triangles[f];
    for (int c = 0; c < 3; ++c) {
      const Vec3 e0 = mesh.positions[t[(c + 1) % 3]] - mesh.positions[t[c]];
      const Vec3 e1 = mesh.positions[t[(c + 2) % 3]] - mesh.positions[t[c]];
      report.min_edge_m = std::min(report.min_edge_m, length(e0));
      report.max_edge_m = std::max(report.max_edge_m, length(e0));
      const double cosine = dot(e0, e1) / (length(e0) * length(e1));
      report.min_angle_deg = std::min(report.min_angle_deg, units::rad_to_deg(std::acos(std::clamp(cosine, -1.0, 1.0))));
    }
  }
  if (options.check_self_intersections) {
    if (Status s = check_self_intersections(mesh); !s) return Error{s.error()};
  }
  if (report.components > 1) {
    if (Status s = check_no_nested_shells(mesh, components, component_first_face); !s) return Error{s.error()};
  }
  return report;
}

}  // namespace resecto
