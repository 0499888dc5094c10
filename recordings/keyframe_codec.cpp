// Draco encoding and decoding of surface keyframes (the mesh, the fixed grid, the node-id attribute).
#include "recordings/keyframe_codec.h"

#include <algorithm>
#include <cmath>

#include <draco/compression/decode.h>
#include <draco/compression/encode.h>
#include <draco/mesh/mesh.h>

namespace resecto::rec {

QuantisationGrid grid_for_bounds(const Vec3& lo, const Vec3& hi, int bits, double margin_m) {
  QuantisationGrid grid;
  const Vec3 extent = hi - lo;
  const double side = std::max({extent.x, extent.y, extent.z}) + 2.0 * margin_m;
  for (int i = 0; i < 3; ++i) grid.origin[i] = static_cast<float>(lo[i] - margin_m);
  grid.range = static_cast<float>(side);
  grid.bits = bits;
  return grid;
}

Status encode_keyframe(std::span<const Vec3> node_positions, std::span<const Triangle> triangles, const QuantisationGrid& grid,
                       const KeyframeCodecSettings& settings, std::vector<std::uint8_t>& out) {
  // Vertices: the nodes the surface uses, in increasing id order (a deterministic numbering).
  std::vector<std::uint32_t> vertex_of(node_positions.size(), UINT32_MAX);
  for (const Triangle& t : triangles) {
    for (std::uint32_t id : t) {
      if (id >= node_positions.size()) return Error{"keyframe: triangle uses node " + std::to_string(id) + " beyond the positions"};
      vertex_of[id] = 0;
    }
  }
  std::vector<std::uint32_t> ids;
  for (std::uint32_t id = 0; id < vertex_of.size(); ++id) {
    if (vertex_of[id] == 0) {
      vertex_of[id] = static_cast<std::uint32_t>(ids.size());
      ids.push_back(id);
    }
  }

  draco::Mesh mesh;
  mesh.set_num_points(static_cast<std::uint32_t>(ids.size()));
  draco::GeometryAttribute position;
  position.Init(draco::GeometryAttribute::POSITION, nullptr, 3, draco::DT_FLOAT32, false, sizeof(float) * 3, 0);
  const int position_id = mesh.AddAttribute(position, true, static_cast<std::uint32_t>(ids.size()));
  draco::GeometryAttribute node_id;
  node_id.Init(draco::GeometryAttribute::GENERIC, nullptr, 1, draco::DT_UINT32, false, sizeof(std::uint32_t), 0);
  const int id_attribute = mesh.AddAttribute(node_id, true, static_cast<std::uint32_t>(ids.size()));
  for (std::uint32_t v = 0; v < ids.size(); ++v) {
    const Vec3& p = node_positions[ids[v]];
    const float xyz[3] = {static_cast<float>(p.x), static_cast<float>(p.y), static_cast<float>(p.z)};
    mesh.attribute(position_id)->SetAttributeValue(draco::AttributeValueIndex(v), xyz);
    mesh.attribute(id_attribute)->SetAttributeValue(draco::AttributeValueIndex(v), &ids[v]);
  }
  mesh.SetNumFaces(triangles.size());
  for (std::size_t f = 0; f < triangles.size(); ++f) {
    draco::Mesh::Face face;
    for (int k = 0; k < 3; ++k) face[k] = draco::PointIndex(vertex_of[triangles[f][static_cast<std::size_t>(k)]]);
    mesh.SetFace(draco::FaceIndex(static_cast<std::uint32_t>(f)), face);
  }

  draco::Encoder encoder;
  encoder.SetSpeedOptions(settings.encode_speed, settings.decode_speed);
  encoder.SetAttributeExplicitQuantization(draco::GeometryAttribute::POSITION, grid.bits, 3, grid.origin, grid.range);
  encoder.SetEncodingMethod(settings.edgebreaker ? draco::MESH_EDGEBREAKER_ENCODING : draco::MESH_SEQUENTIAL_ENCODING);
  draco::EncoderBuffer buffer;
  const draco::Status status = encoder.EncodeMeshToBuffer(mesh, &buffer);
  if (!status.ok()) return Error{std::string("keyframe: Draco could not encode: ") + status.error_msg()};
  out.assign(buffer.data(), buffer.data() + buffer.size());
  return Ok{};
}

Result<SurfaceFrame> decode_keyframe(std::span<const std::uint8_t> draco_bytes) {
  draco::DecoderBuffer buffer;
  buffer.Init(reinterpret_cast<const char*>(draco_bytes.data()), draco_bytes.size());
  draco::Decoder decoder;
  auto decoded = decoder.DecodeMeshFromBuffer(&buffer);
  if (!decoded.ok()) return Error{std::string("keyframe: Draco could not decode: ") + decoded.status().error_msg()};
  const std::unique_ptr<draco::Mesh> mesh = std::move(decoded).value();
  const draco::PointAttribute* position = mesh->GetNamedAttribute(draco::GeometryAttribute::POSITION);
  const draco::PointAttribute* ids = mesh->GetNamedAttribute(draco::GeometryAttribute::GENERIC);
  if (!position || position->num_components() != 3) return Error{"keyframe: no 3D positions"};
  if (!ids || ids->num_components() != 1) return Error{"keyframe: no node ids"};
  SurfaceFrame frame;
  const std::uint32_t points = mesh->num_points();
  frame.positions.resize(points);
  frame.node_ids.resize(points);
  for (std::uint32_t i = 0; i < points; ++i) {
    float xyz[3] = {0, 0, 0};
    std::uint32_t id = 0;
    if (!position->ConvertValue<float, 3>(position->mapped_index(draco::PointIndex(i)), xyz) ||
        !ids->ConvertValue<std::uint32_t, 1>(ids->mapped_index(draco::PointIndex(i)), &id)) {
      return Error{"keyframe: unreadable vertex " + std::to_string(i)};
    }
    frame.positions[i] = Vec3(xyz[0], xyz[1], xyz[2]);
    frame.node_ids[i] = id;
  }
  frame.triangles.resize(mesh->num_faces());
  for (std::uint32_t f = 0; f < mesh->num_faces(); ++f) {
    const draco::Mesh::Face& face = mesh->face(draco::FaceIndex(f));
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t v = face[k].value();
      if (v >= points) return Error{"keyframe: face " + std::to_string(f) + " uses a missing vertex"};
      frame.triangles[f][static_cast<std::size_t>(k)] = v;
    }
  }
  return frame;
}

}  // namespace resecto::rec
