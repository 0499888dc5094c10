// The prostate's tissue model set-up: TetGen on the procedural surface, channel and capsule marked.
#include "rtcore/scenes/prostate_tissue.h"

#include <string>
#include <utility>

#include "rtcore/tissue/tetrahedralize.h"

namespace resecto {

Result<TetMesh> tetrahedralize_prostate(const ProstateModel& anatomy, double max_tet_volume_m3) {
  TetrahedralizeOptions options;
  options.capsule_thickness_m = anatomy.shape.capsule_thickness_m;
  options.channel_axis = {{0.0, 0.0, 0.0}, {0.0, 0.0, anatomy.shape.length_m}};
  options.max_volume_m3 = max_tet_volume_m3;
  Result<TetMesh> mesh = tetrahedralize(anatomy.surface, options);
  if (!mesh) return Error{"prostate of " + std::to_string(anatomy.surface.triangle_count()) + " triangles: " + mesh.error()};
  return mesh;
}

Result<ProstateTissueModel> build_prostate_tissue_model(ProstateModel anatomy, TriangleMesh loop) {
  Result<TetMesh> mesh = tetrahedralize_prostate(anatomy);
  if (!mesh) return Error{mesh.error()};
  ProstateTissueModel model;
  model.anatomy = std::move(anatomy);
  model.mesh = std::move(*mesh);
  model.loop = std::move(loop);
  return model;
}

}  // namespace resecto
