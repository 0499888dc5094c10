// TetMesh: the volumetric tissue model, tetrahedra over shared nodes with a region label each
// (capsule shell or adenoma). Its boundary is the tissue's surface and shares its node indices.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <vector>

#include "rtcore/base/result.h"
#include "rtcore/mesh/triangle_mesh.h"

namespace resecto {

using Tetrahedron = std::array<std::uint32_t, 4>;

/// Anatomical region of a tetrahedron.
enum class TissueRegion : std::uint8_t { kCapsule = 1, kAdenoma = 2 };

/// Tetrahedral mesh in metres; every tetrahedron positively oriented
/// (dot(b - a, cross(c - a, d - a)) > 0).
struct TetMesh {
  std::vector<Vec3> positions;
  std::vector<Tetrahedron> tetrahedra;
  std::vector<TissueRegion> regions;  ///< one per tetrahedron

  std::size_t node_count() const { return positions.size(); }
  std::size_t tetrahedron_count() const { return tetrahedra.size(); }
};

/// Signed volume of tetrahedron t (positive for the orientation above).
double tetrahedron_volume(const TetMesh& mesh, std::size_t t);
/// The six dihedral angles of tetrahedron t, in radians, smallest first.
std::array<double, 6> dihedral_angles(const TetMesh& mesh, std::size_t t);

/// Facts printed by `resecto mesh tetra`.
struct TetMeshStats {
  std::size_t nodes = 0;
  std::size_t tetrahedra = 0;
  double volume_m3 = 0.0;
  double capsule_volume_m3 = 0.0;
  double adenoma_volume_m3 = 0.0;
  double max_tetrahedron_volume_m3 = 0.0;
  double min_dihedral_deg = 0.0;
  double max_dihedral_deg = 0.0;
  double max_radius_edge_ratio = 0.0;
};
TetMeshStats compute_stats(const TetMesh& mesh);

/// Faces that belong to exactly one tetrahedron, oriented outward, over the mesh's own node
/// indices; ordered by (smallest node index, then the others) so it is the same on every run.
TriangleMesh boundary_surface(const TetMesh& mesh);

/// Legacy VTK unstructured grid (ASCII, millimetres) with the region as cell data: opens in
/// ParaView and 3D Slicer. Written to a temporary file and renamed.
Status write_vtk(const std::filesystem::path& path, const TetMesh& mesh);
/// Reads what write_vtk writes; errors name the line at fault.
Result<TetMesh> read_vtk(const std::filesystem::path& path);

}  // namespace resecto
