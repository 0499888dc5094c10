// Validation of closed surfaces: the checks a mesh must pass before it can be a tissue or a tool.
#pragma once

#include <string>

#include "rtcore/base/result.h"
#include "rtcore/mesh/triangle_mesh.h"

namespace resecto {

/// Topology and geometry facts of a surface.
struct SurfaceReport {
  std::size_t vertices = 0;         ///< the vertices the faces use
  std::size_t unused_vertices = 0;  ///< vertices no face uses: no part of the surface, ignored
  std::size_t edges = 0;
  std::size_t triangles = 0;
  int components = 0;
  int euler_characteristic = 0;
  int genus = 0;              ///< of a closed, connected, orientable surface
  double area_m2 = 0.0;
  double volume_m3 = 0.0;     ///< signed; positive when oriented outward
  double min_edge_m = 0.0;
  double max_edge_m = 0.0;
  double min_angle_deg = 0.0;
};

struct ValidationOptions {
  bool check_self_intersections = true;
  /// A triangle whose area is below this fraction of the mean triangle area is degenerate.
  double degenerate_area_fraction = 1e-8;
};

/// Checks that the mesh is closed, 2-manifold, consistently and outwardly oriented, free of
/// degenerate triangles and (optionally) of self-intersections. The error names the first problem
/// and the face or vertex (0-based, file order) where it is.
Result<SurfaceReport> validate_closed_surface(const TriangleMesh& mesh, const ValidationOptions& options = {});

}  // namespace resecto
