// The prostate's tissue model, set up in one place for every user: the simulation's core, the
// indentation scene, the tissue tests and benchmarks and the `resecto tissue` command.
#pragma once

#include "rtcore/anatomy/prostate.h"
#include "rtcore/base/result.h"
#include "rtcore/mesh/triangle_mesh.h"
#include "rtcore/tissue/tet_mesh.h"

namespace resecto {

/// Tetrahedralizes `anatomy` (from generate_prostate) with its channel axis (along z, prostate.h)
/// and capsule shell; `max_tet_volume_m3` is TetGen's -a bound (0: unbounded). The error names the gland.
Result<TetMesh> tetrahedralize_prostate(const ProstateModel& anatomy, double max_tet_volume_m3 = 0.0);

/// The gland as a tetrahedral model, labelled, ready for MassSpringTissue, with the loop that indents it.
struct ProstateTissueModel {
  ProstateModel anatomy;
  TetMesh mesh;
  TriangleMesh loop;  ///< the resectoscope's loop in the tool frame
};
/// The model of `anatomy` (tetrahedralize_prostate, unbounded volume) with `loop` beside it.
Result<ProstateTissueModel> build_prostate_tissue_model(ProstateModel anatomy, TriangleMesh loop);

}  // namespace resecto
