// The resectoscope model of the paper's benchmark: a sheath of 158 triangles and a resecting loop of
// 330 (488 in all). Tool frame: the sheath's axis is +z (the direction of insertion), its tip at the
// origin, the shaft extending toward -z; the loop's wire hangs below the axis (-y) and travels out in
// front of the tip. Drawn fully back it lies just inside the tip, in the slot of the sheath's insulated
// beak, so a loop closed against the sheath has passed through everything it held.
#pragma once

#include <vector>

#include "rtcore/mesh/triangle_mesh.h"

namespace resecto {

/// Dimensions of the tool, metres.
struct ResectoscopeShape {
  double sheath_diameter_m = 0.00867;  ///< 26 Fr
  double sheath_length_m = 0.120;      ///< the distal part that can reach the model
  double loop_span_m = 0.006;          ///< width of the half-ring of wire
  double wire_diameter_m = 0.00035;
  double loop_travel_m = 0.0;          ///< 0 (retracted into the beak) .. 0.036
  /// Where the half-ring's centre line sits along the axis at zero travel: half a millimetre inside
  /// the tip. Its wire is out of the sheath from 0.5 mm of travel on.
  double retracted_loop_z_m = -0.0005;
};

inline constexpr int kSheathTriangles = 158;
inline constexpr int kLoopTriangles = 330;

/// The two rigid parts in the tool frame.
struct ResectoscopeModel {
  TriangleMesh sheath;  ///< closed, 158 triangles
  TriangleMesh loop;    ///< closed, 330 triangles
};

ResectoscopeModel generate_resectoscope(const ResectoscopeShape& shape = {});

/// The cutting part of the loop's wire, its half-ring, as points along its centre line in the loop's
/// frame (the frame of ResectoscopeModel::loop): what resection sweeps. The arms stay in the sheath.
std::vector<Vec3> loop_cutting_arc(const ResectoscopeShape& shape = {});

/// Sheath then loop in one mesh: faces [0, 158) are the sheath, [158, 488) the loop.
TriangleMesh combined_resectoscope_mesh(const ResectoscopeModel& model);

}  // namespace resecto
