// Measures, boundary extraction and VTK files of the tetrahedral tissue model.
#include "rtcore/tissue/tet_mesh.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <numbers>
#include <sstream>
#include <string>
#include <tuple>

#include "rtcore/base/atomic_file.h"
#include "rtcore/base/text_file.h"
#include "rtcore/base/units.h"

namespace resecto {
namespace {

/// The four faces of a positively oriented tetrahedron (a, b, c, d), each wound outward.
constexpr int kOutwardFaces[4][3] = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};

}  // namespace

double tetrahedron_volume(const TetMesh& mesh, std::size_t t) {
  const Tetrahedron& tet = mesh.tetrahedra[t];
  const Vec3& a = mesh.positions[tet[0]];
  return dot(mesh.positions[tet[1]] - a, cross(mesh.positions[tet[2]] - a, mesh.positions[tet[3]] - a)) / 6.0;
}

std::array<double, 6> dihedral_angles(const TetMesh& mesh, std::size_t t) {
  const Tetrahedron& tet = mesh.tetrahedra[t];
  Vec3 normals[4];
  for (int f = 0; f < 4; ++f) {
    const Vec3& a = mesh.positions[tet[kOutwardFaces[f][0]]];
    normals[f] = glm::normalize(cross(mesh.positions[tet[kOutwardFaces[f][1]]] - a, mesh.positions[tet[kOutwardFaces[f][2]]] - a));
  }
  // The dihedral angle at the edge two faces share is pi minus the angle between their outward normals.
  std::array<double, 6> angles{};
  int k = 0;
  for (int f = 0; f < 4; ++f) {
    for (int g = f + 1; g < 4; ++g) {
      angles[k++] = std::numbers::pi - std::acos(std::clamp(dot(normals[f], normals[g]), -1.0, 1.0));
    }
  }
  std::sort(angles.begin(), angles.end());
  return angles;
}

TetMeshStats compute_stats(const TetMesh& mesh) {
  TetMeshStats stats;
  stats.nodes = mesh.node_count();
  stats.tetrahedra = mesh.tetrahedron_count();
  stats.min_dihedral_deg = 180.0;
  for (std::size_t t = 0; t < mesh.tetrahedron_count(); ++t) {
    const double volume = tetrahedron_volume(mesh, t);
    stats.volume_m3 += volume;
    stats.max_tetrahedron_volume_m3 = std::max(stats.max_tetrahedron_volume_m3, volume);
    (mesh.regions[t] == TissueRegion::kCapsule ? stats.capsule_volume_m3 : stats.adenoma_volume_m3) += volume;
    const auto angles = dihedral_angles(mesh, t);
    stats.min_dihedral_deg = std::min(stats.min_dihedral_deg, units::rad_to_deg(angles.front()));
    stats.max_dihedral_deg = std::max(stats.max_dihedral_deg, units::rad_to_deg(angles.back()));
    // Radius-edge ratio: circumradius over the shortest edge.
    const Tetrahedron& tet = mesh.tetrahedra[t];
    const Vec3& a = mesh.positions[tet[0]];
    const Vec3 b = mesh.positions[tet[1]] - a, c = mesh.positions[tet[2]] - a, d = mesh.positions[tet[3]] - a;
    const double det = 2.0 * dot(b, cross(c, d));
    const Vec3 centre = (length_squared(b) * cross(c, d) + length_squared(c) * cross(d, b) + length_squared(d) * cross(b, c)) / det;
    double shortest = 1e300;
    for (int i = 0; i < 4; ++i) {
      for (int j = i + 1; j < 4; ++j) shortest = std::min(shortest, length(mesh.positions[tet[i]] - mesh.positions[tet[j]]));
    }
    stats.max_radius_edge_ratio = std::max(stats.max_radius_edge_ratio, length(centre) / shortest);
  }
  return stats;
}

TriangleMesh boundary_surface(const TetMesh& mesh) {
  struct Face {
    std::array<std::uint32_t, 3> key;  ///< sorted corners: identifies the face
    Triangle wound;                    ///< corners wound outward from its tetrahedron
  };
  std::vector<Face> faces;
  faces.reserve(4 * mesh.tetrahedron_count());
  for (const Tetrahedron& tet : mesh.tetrahedra) {
    for (const auto& f : kOutwardFaces) {
      Face face{{tet[f[0]], tet[f[1]], tet[f[2]]}, {tet[f[0]], tet[f[1]], tet[f[2]]}};
      std::sort(face.key.begin(), face.key.end());
      faces.push_back(face);
    }
  }
  // Keys are unique per face of a valid mesh, so this order is total and the same every run.
  std::sort(faces.begin(), faces.end(), [](const Face& x, const Face& y) { return x.key < y.key; });
  TriangleMesh surface;
  surface.positions = mesh.positions;
  for (std::size_t i = 0; i < faces.size();) {
    std::size_t j = i + 1;
    while (j < faces.size() && faces[j].key == faces[i].key) ++j;
    if (j - i == 1) surface.triangles.push_back(faces[i].wound);
    i = j;
  }
  return surface;
}

Status write_vtk(const std::filesystem::path& path, const TetMesh& mesh) {
  std::ostringstream out(std::ios::out | std::ios::binary);
  out.precision(10);
  out << "# vtk DataFile Version 3.0\nResecto tetrahedral tissue model (millimetres)\nASCII\nDATASET UNSTRUCTURED_GRID\n";
  out << "POINTS " << mesh.node_count() << " double\n";
  for (const Vec3& p : mesh.positions) {
    out << units::m_to_mm(p.x) << ' ' << units::m_to_mm(p.y) << ' ' << units::m_to_mm(p.z) << '\n';
  }
  out << "CELLS " << mesh.tetrahedron_count() << ' ' << 5 * mesh.tetrahedron_count() << '\n';
  for (const Tetrahedron& t : mesh.tetrahedra) out << "4 " << t[0] << ' ' << t[1] << ' ' << t[2] << ' ' << t[3] << '\n';
  out << "CELL_TYPES " << mesh.tetrahedron_count() << '\n';
  for (std::size_t t = 0; t < mesh.tetrahedron_count(); ++t) out << "10\n";
  out << "CELL_DATA " << mesh.tetrahedron_count() << "\nSCALARS region int 1\nLOOKUP_TABLE default\n";
  for (TissueRegion r : mesh.regions) out << static_cast<int>(r) << '\n';
  return write_file_atomically(path, out.view());
}

Result<TetMesh> read_vtk(const std::filesystem::path& path) {
  // Read whole and capped, so every count below can be checked against the bytes there are.
  Result<std::string> text = read_text_file(path, "", std::uintmax_t{1} << 30);
  if (!text) return Error{text.error()};
  std::istringstream in(*text);
  const std::string name = path.string();
  TetMesh mesh;
  std::string line;
  int line_number = 0;
  // A file cut mid-line ends without its newline: say so, it is the likeliest cause of a bad last line.
  auto fail = [&](const std::string& what) {
    return Error{name + ":" + std::to_string(line_number) + ": " + (in.eof() ? "truncated: " : "") + what};
  };
  auto bytes_left = [&]() -> std::size_t {
    const std::streamoff at = in.tellg();
    return at < 0 ? 0 : text->size() - static_cast<std::size_t>(at);
  };
  auto next_line = [&]() {
    ++line_number;
    return static_cast<bool>(std::getline(in, line));
  };
  for (int header = 0; header < 4; ++header) {
    if (!next_line()) return fail("truncated header");
  }
  if (line.find("UNSTRUCTURED_GRID") == std::string::npos) return fail("expected DATASET UNSTRUCTURED_GRID");
  std::size_t cells = 0;
  while (next_line()) {
    std::istringstream words(line);
    std::string keyword;
    words >> keyword;
    if (keyword == "POINTS") {
      std::size_t n = 0;
      if (!(words >> n)) return fail("POINTS without a count");
      if (n > bytes_left() / 6) return fail("POINTS " + std::to_string(n) + " is more than the rest of the file holds (truncated?)");  // "0 0 0\n"
      mesh.positions.resize(n);
      for (std::size_t i = 0; i < n; ++i) {
        if (!next_line()) return fail("truncated: expected " + std::to_string(n) + " points");
        std::istringstream xyz(line);
        double x, y, z;
        if (!(xyz >> x >> y >> z) || !std::isfinite(x) || !std::isfinite(y) || !std::isfinite(z)) return fail("malformed point");
        mesh.positions[i] = Vec3(x, y, z) * units::kMetresPerMillimetre;
      }
    } else if (keyword == "CELLS") {
      if (!(words >> cells)) return fail("CELLS without a count");
      if (cells > bytes_left() / 10) return fail("CELLS " + std::to_string(cells) + " is more than the rest of the file holds (truncated?)");  // "4 0 1 2 3\n"
      mesh.tetrahedra.resize(cells);
      for (std::size_t i = 0; i < cells; ++i) {
        if (!next_line()) return fail("truncated: expected " + std::to_string(cells) + " cells");
        std::istringstream ids(line);
        int corners = 0;
        long long v[4];
        if (!(ids >> corners >> v[0] >> v[1] >> v[2] >> v[3]) || corners != 4) return fail("cell is not a tetrahedron");
        for (int k = 0; k < 4; ++k) {
          if (v[k] < 0 || static_cast<std::size_t>(v[k]) >= mesh.positions.size()) return fail("cell refers to a missing point");
          mesh.tetrahedra[i][k] = static_cast<std::uint32_t>(v[k]);
        }
      }
    } else if (keyword == "LOOKUP_TABLE") {
      mesh.regions.resize(cells);
      for (std::size_t i = 0; i < cells; ++i) {
        if (!next_line()) return fail("truncated: expected " + std::to_string(cells) + " region labels");
        const int label = std::atoi(line.c_str());
        if (label != static_cast<int>(TissueRegion::kCapsule) && label != static_cast<int>(TissueRegion::kAdenoma)) {
          return fail("unknown region label '" + line + "'");
        }
        mesh.regions[i] = static_cast<TissueRegion>(label);
      }
    }
  }
  if (mesh.tetrahedra.empty()) return Error{name + ": no tetrahedra"};
  if (mesh.regions.size() != mesh.tetrahedra.size()) mesh.regions.assign(mesh.tetrahedra.size(), TissueRegion::kAdenoma);
  for (std::size_t t = 0; t < mesh.tetrahedron_count(); ++t) {
    if (!(tetrahedron_volume(mesh, t) > 0.0)) return Error{name + ": tetrahedron " + std::to_string(t) + " is inverted or flat"};
  }
  return mesh;
}

}  // namespace resecto
