// The procedural prostate: an enlarged gland (benign prostatic hyperplasia) as a closed genus-1
// surface, the urethral channel running through it from the bladder neck to the apex, with lateral
// and median lobes bulging into the channel and named landmarks.
//
// World frame (DESIGN.md): x to the patient's left, y anterior, z toward the bladder. The urethral
// channel's axis is the z axis; the apex opening is at z = 0, the bladder neck at z = length.
#pragma once

#include <string>
#include <vector>

#include "rtcore/mesh/triangle_mesh.h"

namespace resecto {

/// Shape of the gland; every length in metres. Defaults: a 45 g hyperplastic gland.
struct ProstateShape {
  double width_m = 0.049;            ///< transverse (x) extent of the gland
  double height_m = 0.0375;          ///< anteroposterior (y) extent
  double length_m = 0.0415;          ///< craniocaudal (z) extent, bladder neck to apex
  double posterior_offset_m = 0.006; ///< gland centre lies posterior (-y) of the urethra
  double apex_taper = 0.30;          ///< fraction by which the gland narrows toward the apex
  double channel_radius_m = 0.0046;  ///< urethral lumen where no lobe bulges (just over 26 Fr / 2)
  double lateral_lobe_bulge_m = 0.0017;  ///< how far each lateral lobe pushes into the lumen
  double median_lobe_bulge_m = 0.0022;   ///< how far the median lobe rises at the bladder neck
  double verumontanum_bulge_m = 0.0008;  ///< the verumontanum's mound on the posterior wall
  double capsule_thickness_m = 0.0025;   ///< the fibromuscular capsule shell
  double tissue_density_kg_m3 = 1050.0;
};

/// A named point of the anatomy, in metres.
struct Landmark {
  std::string name;
  Vec3 position;
  std::string description;
};

/// The generated gland: its closed surface, landmarks and the shape it came from.
struct ProstateModel {
  TriangleMesh surface;
  std::vector<Landmark> landmarks;
  ProstateShape shape;
  int meridian_segments = 0;  ///< grid columns around the channel axis
  int profile_segments = 0;   ///< grid rows around each meridian loop
};

/// Generates a gland with approximately `target_triangles` triangles (within 1% for targets of at
/// least 200). Deterministic: the same arguments give bit-identical output.
ProstateModel generate_prostate(int target_triangles, const ProstateShape& shape = {});

/// Radius of the urethral lumen at height z (metres) in direction theta (radians from +x toward +y),
/// including the lobes' bulges; the channel wall of the generated surface follows it.
double channel_radius_at(const ProstateShape& shape, double z_m, double theta_rad);

/// The landmarks as JSON text (millimetres), the form written beside a mesh file.
std::string landmarks_to_json(const ProstateModel& model);

}  // namespace resecto
