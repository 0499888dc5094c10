// Surface mesh files: read by Resecto's own strict readers (mesh_parse.cpp; OpenMesh's readers drop
// bad faces silently, read NaN as 0 and allocate whatever a header claims), written through OpenMesh
// into memory and then to disk by the one atomic writer.
#include "rtcore/mesh/mesh_io.h"

#include <OpenMesh/Core/IO/IOManager.hh>
#include <OpenMesh/Core/IO/MeshIO.hh>
#include <OpenMesh/Core/Mesh/PolyMesh_ArrayKernelT.hh>
#include <OpenMesh/Core/System/omstream.hh>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <fstream>
#include <sstream>
#include <string>
#include <system_error>
#include <vector>

#include "rtcore/base/atomic_file.h"
#include "rtcore/base/text_file.h"
#include "rtcore/mesh/mesh_parse.h"

namespace resecto {

std::string lower_extension(const std::filesystem::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

bool is_surface_mesh_extension(const std::string& extension) {
  return extension == ".off" || extension == ".obj" || extension == ".ply" || extension == ".stl";
}

namespace {

/// Double-precision points, so a written file carries the positions the generators computed.
struct DoublePrecisionTraits : OpenMesh::DefaultTraits {
  using Point = OpenMesh::Vec3d;
};
using PolyMesh = OpenMesh::PolyMesh_ArrayKernelT<DoublePrecisionTraits>;

/// Silences OpenMesh's own error stream while it runs; its messages lack the file and the place.
class QuietOpenMesh {
 public:
  QuietOpenMesh() { omerr().disable(); omlog().disable(); }
  ~QuietOpenMesh() { omerr().enable(); omlog().enable(); }
};

}  // namespace

Result<TriangleMesh> read_surface_mesh(const std::filesystem::path& path, double metres_per_unit) {
  const std::string name = path.string();
  const std::string ext = lower_extension(path);
  if (!is_surface_mesh_extension(ext)) {
    return Error{name + ": unsupported mesh format '" + ext + "' (expected .off, .obj, .ply or .stl)"};
  }
  Result<std::string> bytes = read_text_file(path, " the mesh", kMaxMeshFileBytes);
  if (!bytes) return Error{bytes.error()};
  const MeshFormat format = ext == ".off" ? MeshFormat::off : ext == ".obj" ? MeshFormat::obj : ext == ".ply" ? MeshFormat::ply : MeshFormat::stl;
  // A binary STL's 80-byte header is free bytes, so only the formats that open with text lose a mark.
  // A Windows "Unicode" save is UTF-16: a PLY always opens with its text header (any binary data comes
  // after it), so its start tells as an OFF's or OBJ's does; an STL is judged by parse_stl, which
  // knows a binary one by its size.
  if (format != MeshFormat::stl) strip_utf8_bom(*bytes);
  if (format != MeshFormat::stl && is_utf16(*bytes)) {
    return Error{name + ": is UTF-16, not UTF-8 text; save it as UTF-8"};
  }
  return parse_surface_mesh(*bytes, format, name, metres_per_unit);
}

Status write_surface_mesh(const std::filesystem::path& path, const TriangleMesh& mesh, double metres_per_unit) {
  const std::string name = path.string();
  const std::string ext = lower_extension(path);
  if (!is_surface_mesh_extension(ext)) {
    return Error{name + ": unsupported mesh format '" + ext + "' (expected .off, .obj, .ply or .stl)"};
  }
  PolyMesh out;
  const double units_per_metre = 1.0 / metres_per_unit;
  for (const Vec3& p : mesh.positions) {
    out.add_vertex(PolyMesh::Point(p.x * units_per_metre, p.y * units_per_metre, p.z * units_per_metre));
  }
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    const Triangle& tri = mesh.triangles[t];
    const OpenMesh::FaceHandle face = out.add_face(OpenMesh::VertexHandle(static_cast<int>(tri[0])),
                                                   OpenMesh::VertexHandle(static_cast<int>(tri[1])),
                                                   OpenMesh::VertexHandle(static_cast<int>(tri[2])));
    if (!face.is_valid()) {
      return Error{name + ": face " + std::to_string(t) + " makes the surface non-manifold; not written"};
    }
  }
  // Rendered in memory, then written through the one atomic writer: OpenMesh's own file writer
  // neither checks its writes nor can be asked why it failed.
  std::ostringstream bytes(std::ios::out | std::ios::binary);
  bool rendered = false;
  {
    QuietOpenMesh quiet;
    OpenMesh::IO::Options options;
    if (ext == ".stl") options += OpenMesh::IO::Options::Binary;
    rendered = OpenMesh::IO::write_mesh(out, bytes, ext, options, 9);
  }
  if (!rendered) return Error{name + ": OpenMesh cannot render the mesh as " + ext.substr(1)};
  return write_file_atomically(path, bytes.view());
}

}  // namespace resecto
