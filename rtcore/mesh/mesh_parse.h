// The surface mesh readers (OFF, OBJ, PLY, STL) over bytes in memory: strict, bounded and total.
// Every count or length read from a file is checked against the bytes left before anything is
// allocated, every number must be finite, every index in range, and a file that ends early or
// carries more than it declared is an error naming the place (file:line:column, or the byte offset
// in binary files). OpenMesh's own readers are not used: they drop bad faces silently, read NaN as
// 0, allocate whatever a header claims and accept truncated files.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>

#include "rtcore/base/result.h"
#include "rtcore/mesh/triangle_mesh.h"

namespace resecto {

/// Caps on what a surface file may declare (beyond the bound its own size sets).
inline constexpr std::size_t kMaxMeshFileBytes = std::size_t{1} << 30;  ///< 1 GiB
inline constexpr std::size_t kMaxMeshVertices = 20'000'000;
inline constexpr std::size_t kMaxMeshFaces = 20'000'000;
inline constexpr std::size_t kMaxPolygonCorners = 1024;

/// Mesh file formats by their lower-case extension without the dot.
enum class MeshFormat { off, obj, ply, stl };

/// Parses a whole file's bytes; `name` prefixes every error. Coordinates are scaled by
/// `metres_per_unit`; polygons become fans around their first corner, in file order. STL's
/// unshared corners are merged where their coordinates are identical. A coordinate beyond
/// kMaxSurfaceCoordinateMm is an error naming the vertex.
Result<TriangleMesh> parse_surface_mesh(std::string_view bytes, MeshFormat format, const std::string& name,
                                        double metres_per_unit);

}  // namespace resecto
