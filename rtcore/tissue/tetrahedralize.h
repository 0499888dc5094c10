// Tetrahedralization of a closed surface with TetGen (library mode), and region labelling.
#pragma once

#include <optional>

#include "rtcore/base/result.h"
#include "rtcore/mesh/triangle_mesh.h"
#include "rtcore/tissue/tet_mesh.h"

namespace resecto {

/// TetGen's quality constraints and the capsule labelling, SI units.
struct TetrahedralizeOptions {
  double max_radius_edge_ratio = 1.8;   ///< TetGen's -q bound (>= 1.0; smaller is better shaped)
  double min_dihedral_deg = 10.0;       ///< TetGen's -q second bound
  double max_volume_m3 = 0.0;           ///< TetGen's -a bound; 0 = no volume constraint
  double capsule_thickness_m = 0.0025;  ///< tetrahedra whose centroid is this close to the outer surface are capsule
  /// The urethral channel's axis (apex point, bladder-neck point): boundary faces facing it are the
  /// channel wall, not the capsule. Without it, every boundary face is outer surface.
  std::optional<std::pair<Vec3, Vec3>> channel_axis;
  /// Most points TetGen's refinement may add (-S); reaching it is an error. 0 = kSteinerPointsPerSurfaceVertex
  /// per surface vertex plus two per max_volume_m3 of the enclosed volume, within [kMinSteinerPoints,
  /// kMaxSteinerPoints] (the last about 4 GB of TetGen's memory).
  int max_steiner_points = 0;
  static constexpr double kSteinerPointsPerSurfaceVertex = 50.0;
  static constexpr int kMinSteinerPoints = 20'000;
  static constexpr int kMaxSteinerPoints = 4'000'000;
  /// The most tetrahedra a volume bound may ask for (the enclosed volume over max_volume_m3): past it
  /// the bound is refused at once, before TetGen's minutes and gigabytes.
  static constexpr int kMaxTetrahedraForVolumeBound = 3'000'000;
};

/// Fills the closed surface with tetrahedra, keeping its boundary faces exactly (TetGen -pY), so the
/// tissue's surface is the input surface (over the vertices its faces use, renumbered in order when
/// some are unused). Errors: a surface TetGen cannot mesh (self-intersecting, open), reported with
/// TetGen's reason; a volume bound past kMaxTetrahedraForVolumeBound; quality bounds the refinement
/// could not reach within max_steiner_points.
Result<TetMesh> tetrahedralize(const TriangleMesh& surface, const TetrahedralizeOptions& options = {});

}  // namespace resecto
