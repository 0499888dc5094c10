// Surface mesh files through OpenMesh. Reading goes through a raw importer rather than an OpenMesh
// mesh: OpenMesh's own mesh silently drops or duplicates non-manifold faces, which would hide the very
// defects validation must name. The importer keeps every vertex and face in file order.
#include "rtcore/mesh/mesh_io.h"

#include <OpenMesh/Core/IO/IOManager.hh>
#include <OpenMesh/Core/IO/MeshIO.hh>
#include <OpenMesh/Core/IO/importer/BaseImporter.hh>
#include <OpenMesh/Core/Mesh/PolyMesh_ArrayKernelT.hh>
#include <OpenMesh/Core/System/omstream.hh>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <fstream>
#include <string>
#include <system_error>
#include <vector>

namespace resecto {
namespace {

/// Collects the raw vertex and face lists OpenMesh's readers parse; everything else is ignored.
class RawSurfaceImporter final : public OpenMesh::IO::BaseImporter {
 public:
  using VertexHandle = OpenMesh::VertexHandle;
  using FaceHandle = OpenMesh::FaceHandle;
  using HalfedgeHandle = OpenMesh::HalfedgeHandle;
  using EdgeHandle = OpenMesh::EdgeHandle;

  std::vector<OpenMesh::Vec3d> points;
  std::vector<std::vector<int>> faces;

  VertexHandle add_vertex(const OpenMesh::Vec3f& p) override { return add_vertex(OpenMesh::Vec3d(p)); }
  VertexHandle add_vertex(const OpenMesh::Vec3d& p) override {
    points.push_back(p);
    return VertexHandle(static_cast<int>(points.size()) - 1);
  }
  VertexHandle add_vertex() override { return add_vertex(OpenMesh::Vec3d(0.0, 0.0, 0.0)); }
  HalfedgeHandle add_edge(VertexHandle, VertexHandle) override { return HalfedgeHandle(); }
  FaceHandle add_face(const VHandles& indices) override {
    std::vector<int> face;
    face.reserve(indices.size());
    for (const VertexHandle& vh : indices) face.push_back(vh.idx());
    faces.push_back(std::move(face));
    return FaceHandle(static_cast<int>(faces.size()) - 1);
  }
  FaceHandle add_face(HalfedgeHandle) override { return FaceHandle(); }
  void set_point(VertexHandle vh, const OpenMesh::Vec3f& p) override {
    if (vh.idx() >= 0 && static_cast<std::size_t>(vh.idx()) < points.size()) points[vh.idx()] = OpenMesh::Vec3d(p);
  }

  // Attributes the simulator does not use.
  void add_face_texcoords(FaceHandle, VertexHandle, const std::vector<OpenMesh::Vec2f>&) override {}
  void add_face_texcoords(FaceHandle, VertexHandle, const std::vector<OpenMesh::Vec3f>&) override {}
  void set_face_texindex(FaceHandle, int) override {}
  void set_halfedge(VertexHandle, HalfedgeHandle) override {}
  void set_normal(VertexHandle, const OpenMesh::Vec3f&) override {}
  void set_normal(VertexHandle, const OpenMesh::Vec3d&) override {}
  void set_color(VertexHandle, const OpenMesh::Vec3uc&) override {}
  void set_color(VertexHandle, const OpenMesh::Vec4uc&) override {}
  void set_color(VertexHandle, const OpenMesh::Vec3f&) override {}
  void set_color(VertexHandle, const OpenMesh::Vec4f&) override {}
  void set_texcoord(VertexHandle, const OpenMesh::Vec2f&) override {}
  void set_status(VertexHandle, const OpenMesh::Attributes::StatusInfo&) override {}
  void set_next(HalfedgeHandle, HalfedgeHandle) override {}
  void set_face(HalfedgeHandle, FaceHandle) override {}
  void request_face_texcoords2D() override {}
  void set_texcoord(HalfedgeHandle, const OpenMesh::Vec2f&) override {}
  void set_texcoord(VertexHandle, const OpenMesh::Vec3f&) override {}
  void set_texcoord(HalfedgeHandle, const OpenMesh::Vec3f&) override {}
  void set_status(HalfedgeHandle, const OpenMesh::Attributes::StatusInfo&) override {}
  void set_color(EdgeHandle, const OpenMesh::Vec3uc&) override {}
  void set_color(EdgeHandle, const OpenMesh::Vec4uc&) override {}
  void set_color(EdgeHandle, const OpenMesh::Vec3f&) override {}
  void set_color(EdgeHandle, const OpenMesh::Vec4f&) override {}
  void set_status(EdgeHandle, const OpenMesh::Attributes::StatusInfo&) override {}
  void set_normal(FaceHandle, const OpenMesh::Vec3f&) override {}
  void set_normal(FaceHandle, const OpenMesh::Vec3d&) override {}
  void set_color(FaceHandle, const OpenMesh::Vec3uc&) override {}
  void set_color(FaceHandle, const OpenMesh::Vec4uc&) override {}
  void set_color(FaceHandle, const OpenMesh::Vec3f&) override {}
  void set_color(FaceHandle, const OpenMesh::Vec4f&) override {}
  void set_status(FaceHandle, const OpenMesh::Attributes::StatusInfo&) override {}
  void add_texture_information(int, std::string) override {}
  size_t n_vertices() const override { return points.size(); }
  size_t n_faces() const override { return faces.size(); }
  size_t n_edges() const override { return 0; }
};

std::string lower_extension(const std::filesystem::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

bool is_supported_extension(const std::string& ext) {
  return ext == ".off" || ext == ".obj" || ext == ".ply" || ext == ".stl";
}

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
  if (!is_supported_extension(ext)) {
    return Error{name + ": unsupported mesh format '" + ext + "' (expected .off, .obj, .ply or .stl)"};
  }
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) return Error{name + ": no such file"};
  if (std::filesystem::file_size(path, ec) == 0) return Error{name + ": file is empty"};

  RawSurfaceImporter importer;
  OpenMesh::IO::Options options;
  bool parsed = false;
  {
    QuietOpenMesh quiet;
    parsed = OpenMesh::IO::IOManager().read(name, importer, options);
  }
  if (!parsed) return Error{name + ": not a readable " + ext.substr(1) + " mesh (OpenMesh could not parse it)"};
  if (importer.faces.empty()) return Error{name + ": the file holds no faces"};

  TriangleMesh mesh;
  mesh.positions.reserve(importer.points.size());
  for (std::size_t v = 0; v < importer.points.size(); ++v) {
    const OpenMesh::Vec3d& p = importer.points[v];
    if (!std::isfinite(p[0]) || !std::isfinite(p[1]) || !std::isfinite(p[2])) {
      return Error{name + ": vertex " + std::to_string(v) + " has a non-finite coordinate"};
    }
    mesh.positions.push_back(Vec3(p[0], p[1], p[2]) * metres_per_unit);
  }
  const auto vertex_count = static_cast<int>(importer.points.size());
  // Faces keep file order; a polygon becomes a fan around its first corner, also in file order.
  for (std::size_t f = 0; f < importer.faces.size(); ++f) {
    const std::vector<int>& face = importer.faces[f];
    if (face.size() < 3) {
      return Error{name + ": face " + std::to_string(f) + " has " + std::to_string(face.size()) + " corners"};
    }
    for (int v : face) {
      if (v < 0 || v >= vertex_count) {
        return Error{name + ": face " + std::to_string(f) + " refers to vertex " + std::to_string(v) +
                     ", but the file has " + std::to_string(vertex_count) + " vertices"};
      }
    }
    for (std::size_t corner = 1; corner + 1 < face.size(); ++corner) {
      mesh.triangles.push_back({static_cast<std::uint32_t>(face[0]), static_cast<std::uint32_t>(face[corner]),
                                static_cast<std::uint32_t>(face[corner + 1])});
    }
  }
  return mesh;
}

Status write_surface_mesh(const std::filesystem::path& path, const TriangleMesh& mesh, double metres_per_unit) {
  const std::string name = path.string();
  const std::string ext = lower_extension(path);
  if (!is_supported_extension(ext)) {
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
  // Write beside the target and rename, so a failed write never clobbers an existing file.
  std::filesystem::path temporary = path;
  temporary += ".partial" + ext;
  bool written = false;
  {
    QuietOpenMesh quiet;
    OpenMesh::IO::Options options;
    if (ext == ".stl") options += OpenMesh::IO::Options::Binary;
    written = OpenMesh::IO::write_mesh(out, temporary.string(), options, 9);
  }
  std::error_code ec;
  if (!written) {
    std::filesystem::remove(temporary, ec);
    return Error{name + ": cannot write the mesh (is the folder writable?)"};
  }
  std::filesystem::rename(temporary, path, ec);
  if (ec) {
    std::filesystem::remove(temporary, ec);
    return Error{name + ": cannot replace the file: " + ec.message()};
  }
  return Ok{};
}

}  // namespace resecto
