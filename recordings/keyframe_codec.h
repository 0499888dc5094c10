// Keyframes: the tissue surface at one collision step, compressed with Draco as a triangle mesh whose
// vertices carry their mesh node ids (a generic uint32 attribute), so two keyframes match vertex by
// vertex whatever order Draco's connectivity coder puts them in. Positions sit on one fixed
// quantisation grid (origin and range from the gland's bounds, set explicitly) shared by every
// keyframe of a recording: equal positions give equal codes, and keyframes compare exactly.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "rtcore/base/result.h"
#include "rtcore/geometry/vec3.h"
#include "rtcore/mesh/triangle_mesh.h"

namespace resecto::rec {

/// A cube of side `range` from `origin` (metres), split into 2^bits steps per axis.
struct QuantisationGrid {
  float origin[3] = {0.0f, 0.0f, 0.0f};
  float range = 1.0f;
  int bits = 14;
  double step_m() const { return static_cast<double>(range) / static_cast<double>((1u << bits) - 1u); }
};

/// The grid for a gland: its bounding box grown by `margin_m` on every side (the tissue moves, and
/// resection exposes inner nodes, all inside the capsule's reach).
QuantisationGrid grid_for_bounds(const Vec3& lo, const Vec3& hi, int bits, double margin_m);

/// Draco's knobs, chosen by recording_bench (README "Recordings: codec settings").
struct KeyframeCodecSettings {
  int encode_speed = 5;         ///< 0 (smallest) .. 10 (fastest)
  int decode_speed = 5;
  bool edgebreaker = true;      ///< else Draco's sequential connectivity
};

/// A decoded keyframe: vertices (with their node ids) and triangles over those vertices.
struct SurfaceFrame {
  std::vector<Vec3> positions;
  std::vector<std::uint32_t> node_ids;  ///< node_ids[i]: mesh node id of vertex i
  std::vector<Triangle> triangles;      ///< over vertex indices
};

/// Encodes the surface `triangles` (over node ids) with the positions `node_positions` (by node id)
/// into `out`. Only the nodes the triangles use become vertices, in increasing id order.
Status encode_keyframe(std::span<const Vec3> node_positions, std::span<const Triangle> triangles, const QuantisationGrid& grid,
                       const KeyframeCodecSettings& settings, std::vector<std::uint8_t>& out);

/// Decodes a keyframe's Draco bytes; an error for anything Draco rejects or a mesh without node ids.
Result<SurfaceFrame> decode_keyframe(std::span<const std::uint8_t> draco_bytes);

}  // namespace resecto::rec
