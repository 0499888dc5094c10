// Reading and writing surface meshes (OFF, OBJ, PLY, STL) through OpenMesh. Files are in millimetres
// unless the caller says otherwise; the mesh in memory is in metres.
#pragma once

#include <filesystem>

#include "rtcore/base/result.h"
#include "rtcore/mesh/triangle_mesh.h"

namespace resecto {

inline constexpr double kMillimetreFile = 1e-3;  ///< metres per file unit for millimetre files

/// A path's extension in lower case (".OFF" -> ".off"): formats are chosen by it.
std::string lower_extension(const std::filesystem::path& path);
/// Whether read_surface_mesh() and write_surface_mesh() take files with this (lower-case) extension.
bool is_surface_mesh_extension(const std::string& extension);

/// Reads a surface mesh: polygons are fan-triangulated in file order, faces keep file order.
/// Only parsing errors fail here; call validate_closed_surface() for the topology checks.
Result<TriangleMesh> read_surface_mesh(const std::filesystem::path& path,
                                       double metres_per_unit = kMillimetreFile);

/// Writes a surface mesh; format by extension (.off, .obj, .ply, .stl). Written to a temporary
/// file first and renamed, so a failure never leaves a half-written file behind.
Status write_surface_mesh(const std::filesystem::path& path, const TriangleMesh& mesh,
                          double metres_per_unit = kMillimetreFile);

}  // namespace resecto
