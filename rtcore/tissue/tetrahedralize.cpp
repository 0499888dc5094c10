// TetGen in library mode: the closed surface in, quality tetrahedra out, boundary kept exactly (-pY)
// so the tissue's surface stays the surface the user gave. TetGen reports failure by throwing an int;
// every such code becomes a clear error here, and never an exit() from inside the library.
#include "rtcore/tissue/tetrahedralize.h"

#include <tetgen.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <tuple>
#include <vector>

#include "rtcore/base/units.h"
#include "rtcore/geometry/closest_point.h"
#include "rtcore/mesh/mesh_validation.h"

namespace resecto {
namespace {

std::string tetgen_failure(int code) {
  switch (code) {
    case 1: return "TetGen ran out of memory";
    case 2: return "TetGen hit an internal error (please report the mesh)";
    case 3: return "the surface intersects itself";
    case 4: return "the surface has features too small for TetGen's tolerance";
    case 5: return "the surface has two very close but separate facets";
    case 10: return "the surface is not closed or has overlapping faces";
    default: return "TetGen failed with code " + std::to_string(code);
  }
}

/// Uniform grid over the outer surface's faces, to answer "is this point within d of the outer
/// surface?" by visiting only nearby faces. Cells are kept as a sorted (cell, face) list so lookups
/// and their order are deterministic. The grid only narrows the search: the answer is the exact
/// distance test, whatever the cell size (at least the reach, so the 27 cells around a point hold
/// every face within reach of it).
class OuterSurfaceProximity {
 public:
  /// On average a face's box may cover this many cells; past it the cells grow.
  static constexpr double kCellsPerFace = 64.0;

  OuterSurfaceProximity(const TriangleMesh& surface, std::vector<std::uint32_t> faces, double reach_m)
      : surface_(surface), reach_m_(reach_m), cell_m_(bounded_cell_m(surface, faces, reach_m)) {
    for (std::uint32_t f : faces) {
      const auto [a, b] = cell_span(face_box(surface, f), cell_m_);
      for (long long x = a[0]; x <= b[0]; ++x)
        for (long long y = a[1]; y <= b[1]; ++y)
          for (long long z = a[2]; z <= b[2]; ++z) entries_.push_back({key(x, y, z), f});
    }
    std::sort(entries_.begin(), entries_.end());
  }

  bool within_reach(const Vec3& p) const {
    const auto c = cell_of(p);
    const double reach2 = reach_m_ * reach_m_;
    for (long long dx = -1; dx <= 1; ++dx)
      for (long long dy = -1; dy <= 1; ++dy)
        for (long long dz = -1; dz <= 1; ++dz) {
          const std::uint64_t k = key(c[0] + dx, c[1] + dy, c[2] + dz);
          auto it = std::lower_bound(entries_.begin(), entries_.end(), std::make_pair(k, std::uint32_t{0}));
          for (; it != entries_.end() && it->first == k; ++it) {
            const Triangle& t = surface_.triangles[it->second];
            const Vec3 q = closest_point_on_triangle(p, surface_.positions[t[0]], surface_.positions[t[1]], surface_.positions[t[2]]);
            if (length_squared(q - p) <= reach2) return true;
          }
        }
    return false;
  }

 private:
  using Cell = std::array<long long, 3>;

  static Aabb face_box(const TriangleMesh& surface, std::uint32_t f) {
    const Triangle& t = surface.triangles[f];
    return triangle_box(surface.positions[t[0]], surface.positions[t[1]], surface.positions[t[2]]);
  }
  static Cell cell_of(const Vec3& p, double cell_m) {
    return {static_cast<long long>(std::floor(p.x / cell_m)), static_cast<long long>(std::floor(p.y / cell_m)),
            static_cast<long long>(std::floor(p.z / cell_m))};
  }
  static std::pair<Cell, Cell> cell_span(const Aabb& box, double cell_m) { return {cell_of(box.min, cell_m), cell_of(box.max, cell_m)}; }
  Cell cell_of(const Vec3& p) const { return cell_of(p, cell_m_); }

  /// The reach (at least 1 um), doubled until the faces' boxes cover at most kCellsPerFace cells
  /// each on average: a thin shell or a wide surface once asked for one entry per micrometre cell
  /// (16.8 GB for a capsule of 0 mm on a 10 mm tetrahedron). Bounded: once cells outgrow every box,
  /// each box covers at most 8.
  static double bounded_cell_m(const TriangleMesh& surface, const std::vector<std::uint32_t>& faces, double reach_m) {
    double cell_m = std::max(reach_m, 1e-6);
    const double budget = kCellsPerFace * static_cast<double>(faces.size());
    for (int doubling = 0; doubling < 1100; ++doubling, cell_m *= 2.0) {
      double cells = 0.0;
      for (std::uint32_t f : faces) {
        const auto [a, b] = cell_span(face_box(surface, f), cell_m);
        cells += static_cast<double>(b[0] - a[0] + 1) * static_cast<double>(b[1] - a[1] + 1) * static_cast<double>(b[2] - a[2] + 1);
      }
      if (cells <= budget) break;
    }
    return cell_m;
  }
  static std::uint64_t key(long long x, long long y, long long z) {
    auto part = [](long long v) { return static_cast<std::uint64_t>(v + (1 << 20)) & 0x1FFFFF; };
    return (part(x) << 42) | (part(y) << 21) | part(z);
  }

  const TriangleMesh& surface_;
  double reach_m_;
  double cell_m_;
  std::vector<std::pair<std::uint64_t, std::uint32_t>> entries_;
};

/// Faces of the outer gland wall: all of them, unless a channel axis says which face the lumen.
std::vector<std::uint32_t> outer_faces(const TriangleMesh& surface, const TetrahedralizeOptions& options) {
  std::vector<std::uint32_t> faces;
  for (std::size_t f = 0; f < surface.triangle_count(); ++f) {
    bool outer = true;
    if (options.channel_axis) {
      const auto& [apex, neck] = *options.channel_axis;
      const Vec3 axis = glm::normalize(neck - apex);
      const Triangle& t = surface.triangles[f];
      const Vec3 centroid = (surface.positions[t[0]] + surface.positions[t[1]] + surface.positions[t[2]]) / 3.0;
      Vec3 radial = centroid - apex;
      radial -= dot(radial, axis) * axis;
      const double r = length(radial);
      // The channel wall faces the axis: its outward normal points back toward it.
      outer = !(r > 0.0 && dot(glm::normalize(triangle_normal_x2(surface, f)), radial / r) < -0.5);
    }
    if (outer) faces.push_back(static_cast<std::uint32_t>(f));
  }
  return faces;
}

/// How many points TetGen's refinement may add (its -S). Tight bounds (a radius-edge ratio near 1,
/// dihedral angles near 30 degrees) make it refine without end on a plain icosphere; the budget
/// turns that into an error after bounded work. Reachable bounds need far less: the procedural
/// gland adds about 2 points per surface vertex at --min-dihedral 18, and a volume bound about one
/// per max_volume of the enclosed volume.
int steiner_point_budget(const TriangleMesh& surface, double volume_m3, const TetrahedralizeOptions& options) {
  if (options.max_steiner_points > 0) return options.max_steiner_points;
  double budget = TetrahedralizeOptions::kSteinerPointsPerSurfaceVertex * static_cast<double>(surface.vertex_count());
  if (options.max_volume_m3 > 0.0) budget += 2.0 * volume_m3 / options.max_volume_m3;
  return static_cast<int>(std::clamp(budget, static_cast<double>(TetrahedralizeOptions::kMinSteinerPoints),
                                     static_cast<double>(TetrahedralizeOptions::kMaxSteinerPoints)));
}

/// The error when refinement stopped at the budget: what was asked and what was reached.
std::string quality_not_met(const TetMesh& mesh, const TetrahedralizeOptions& options, int budget) {
  const TetMeshStats stats = compute_stats(mesh);
  char text[320];
  std::snprintf(text, sizeof text,
                "TetGen's refinement added its limit of %d points without reaching a radius-edge ratio of %.3g and dihedral "
                "angles of %.3g deg (reached %.3g and %.3g deg); loosen the radius-edge, dihedral or volume bound",
                budget, options.max_radius_edge_ratio, options.min_dihedral_deg, stats.max_radius_edge_ratio, stats.min_dihedral_deg);
  return text;
}

}  // namespace

Result<TetMesh> tetrahedralize(const TriangleMesh& input, const TetrahedralizeOptions& options) {
  if (!(options.max_radius_edge_ratio >= 1.0)) return Error{"radius-edge ratio bound must be at least 1.0"};
  if (!(options.min_dihedral_deg >= 0.0 && options.min_dihedral_deg < 70.0)) return Error{"minimum dihedral angle must be in [0, 70) degrees"};
  if (!(options.max_volume_m3 >= 0.0)) return Error{"maximum tetrahedron volume must not be negative"};
  if (!(options.capsule_thickness_m >= 0.0)) return Error{"capsule thickness must not be negative"};
  // TetGen can crash (not throw) on some invalid surfaces, so nothing invalid reaches it.
  Result<SurfaceReport> valid = validate_closed_surface(input);
  if (!valid) return Error{"cannot tetrahedralize: " + valid.error()};
  // A volume bound that asks for more tetrahedra than any model here uses is refused before TetGen
  // spends minutes and gigabytes on it (--max-volume 0.001 in a 42 ml gland asks for 42 million).
  if (options.max_volume_m3 > 0.0) {
    const double volume_m3 = std::abs(valid->volume_m3);
    const double asked = volume_m3 / options.max_volume_m3;
    if (asked > static_cast<double>(TetrahedralizeOptions::kMaxTetrahedraForVolumeBound)) {
      char text[320];
      std::snprintf(text, sizeof text,
                    "maximum tetrahedron volume %.4g mm^3 asks for about %.3g tetrahedra in this surface's %.4g mm^3; at most %d are made "
                    "(the 138,240-triangle gland has about 533,000): give %.3g mm^3 or more",
                    options.max_volume_m3 * 1e9, asked, volume_m3 * 1e9, TetrahedralizeOptions::kMaxTetrahedraForVolumeBound,
                    volume_m3 * 1e9 / TetrahedralizeOptions::kMaxTetrahedraForVolumeBound);
      return Error{text};
    }
  }
  // Only the vertices the faces use reach TetGen: an unused one inside would become a node (and
  // slivers around it), one outside the hull crashes TetGen's cleanup.
  const TriangleMesh surface = without_unused_vertices(input);

  // TetGen works in millimetres: its tolerances are tuned for coordinates of order one.
  tetgenio in;
  in.firstnumber = 0;
  in.numberofpoints = static_cast<int>(surface.vertex_count());
  in.pointlist = new REAL[3 * surface.vertex_count()];
  for (std::size_t v = 0; v < surface.vertex_count(); ++v) {
    for (int k = 0; k < 3; ++k) in.pointlist[3 * v + k] = units::m_to_mm(surface.positions[v][k]);
  }
  in.numberoffacets = static_cast<int>(surface.triangle_count());
  in.facetlist = new tetgenio::facet[surface.triangle_count()];
  for (std::size_t f = 0; f < surface.triangle_count(); ++f) {
    tetgenio::facet& facet = in.facetlist[f];
    tetgenio::init(&facet);
    facet.numberofpolygons = 1;
    facet.polygonlist = new tetgenio::polygon[1];
    tetgenio::init(&facet.polygonlist[0]);
    facet.polygonlist[0].numberofvertices = 3;
    facet.polygonlist[0].vertexlist = new int[3];
    for (int k = 0; k < 3; ++k) facet.polygonlist[0].vertexlist[k] = static_cast<int>(surface.triangles[f][k]);
  }

  char switches[128];
  const double max_volume_mm3 = options.max_volume_m3 * 1e9;
  if (max_volume_mm3 > 0.0) {
    std::snprintf(switches, sizeof switches, "pYq%.4g/%.4ga%.6gQ", options.max_radius_edge_ratio, options.min_dihedral_deg, max_volume_mm3);
  } else {
    std::snprintf(switches, sizeof switches, "pYq%.4g/%.4gQ", options.max_radius_edge_ratio, options.min_dihedral_deg);
  }
  const int steiner_budget = steiner_point_budget(surface, valid->volume_m3, options);
  tetgenio out;
  try {
    tetgenbehavior behaviour;
    if (!behaviour.parse_commandline(switches)) return Error{std::string("TetGen rejected the switches ") + switches};
    behaviour.steinerleft = steiner_budget;  // -S: the quality refinement stops here
    ::tetrahedralize(&behaviour, &in, &out);
  } catch (int code) {
    return Error{"tetrahedralization failed: " + tetgen_failure(code)};
  }
  if (out.numberoftetrahedra <= 0 || out.numberofcorners != 4) return Error{"tetrahedralization produced no tetrahedra"};

  TetMesh mesh;
  mesh.positions.resize(static_cast<std::size_t>(out.numberofpoints));
  for (int v = 0; v < out.numberofpoints; ++v) {
    mesh.positions[v] = Vec3(out.pointlist[3 * v], out.pointlist[3 * v + 1], out.pointlist[3 * v + 2]) * units::kMetresPerMillimetre;
  }
  // -Y keeps every input point, first and in order: give them back their exact input coordinates
  // (the trip through millimetres rounds), so the tissue surface is bit-identical to the input.
  if (mesh.positions.size() < surface.vertex_count()) return Error{"TetGen dropped input vertices"};
  std::copy(surface.positions.begin(), surface.positions.end(), mesh.positions.begin());
  mesh.tetrahedra.resize(static_cast<std::size_t>(out.numberoftetrahedra));
  for (int t = 0; t < out.numberoftetrahedra; ++t) {
    Tetrahedron& tet = mesh.tetrahedra[t];
    for (int k = 0; k < 4; ++k) tet[k] = static_cast<std::uint32_t>(out.tetrahedronlist[4 * t + k] - out.firstnumber);
  }
  for (std::size_t t = 0; t < mesh.tetrahedron_count(); ++t) {
    if (tetrahedron_volume(mesh, t) < 0.0) std::swap(mesh.tetrahedra[t][2], mesh.tetrahedra[t][3]);
  }

  const OuterSurfaceProximity outer(surface, outer_faces(surface, options), options.capsule_thickness_m);
  mesh.regions.resize(mesh.tetrahedron_count());
  for (std::size_t t = 0; t < mesh.tetrahedron_count(); ++t) {
    const Tetrahedron& tet = mesh.tetrahedra[t];
    const Vec3 centroid = 0.25 * (mesh.positions[tet[0]] + mesh.positions[tet[1]] + mesh.positions[tet[2]] + mesh.positions[tet[3]]);
    mesh.regions[t] = outer.within_reach(centroid) ? TissueRegion::kCapsule : TissueRegion::kAdenoma;
  }
  if (out.numberofpoints - static_cast<int>(surface.vertex_count()) >= steiner_budget) {
    return Error{quality_not_met(mesh, options, steiner_budget)};
  }
  return mesh;
}

}  // namespace resecto
