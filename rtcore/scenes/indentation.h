// The virtual indentation test, a shared scene for the `resecto tissue indent` command, the tissue
// tests and the benchmark: the resectoscope's loop presses into the left lateral lobe, holds,
// withdraws, and the tissue relaxes, the way tissue stiffness is measured in the literature.
#pragma once

#include <cstdint>
#include <functional>
#include <vector>

#include "rtcore/anatomy/prostate.h"
#include "rtcore/geometry/rigid_pose.h"
#include "rtcore/scenes/prostate_tissue.h"
#include "rtcore/tissue/mass_spring.h"

namespace resecto {

/// Pose of the loop (in the tool frame of generate_resectoscope) rolled so its wire hangs toward +x,
/// its outermost point touching the left lateral lobe's crest, moved `depth_m` further along +x.
RigidPose indentation_loop_pose(const ProstateModel& anatomy, const TriangleMesh& loop, double depth_m);

/// The protocol and the solver set-up.
struct IndentationOptions {
  double depth_m = 0.005;
  double press_s = 1.0, hold_s = 1.0, withdraw_s = 1.0, relax_s = 3.0;
  double withdraw_clearance_m = 0.001;  ///< the loop ends this far short of first touch
  int collision_hz = 60;
  int substeps = 16;  ///< physics steps per collision step
  TissueParameters parameters;
  TissueConfig config;
  double rest_tolerance_m = 1e-4;  ///< "back at rest": every node within this of its rest position
  /// Called after every collision step with its index and the state hash (e.g. for a determinism check).
  std::function<void(std::int64_t, std::uint64_t)> on_collision_step;
};

/// One point of the force-depth curve, sampled at every collision step.
struct IndentationSample {
  double time_s = 0.0;
  double depth_m = 0.0;  ///< the loop's advance past first touch (negative: clear of it)
  double force_n = 0.0;  ///< the tissue's push back on the loop, along the pressing direction
};

struct IndentationResult {
  std::size_t nodes = 0, tetrahedra = 0, springs = 0, surface_triangles = 0;
  std::vector<IndentationSample> curve;
  double peak_force_n = 0.0;
  double max_displacement_m = 0.0;  ///< over the run
  double residual_m = 0.0;          ///< largest node offset from rest at the end
  double settle_time_s = -1.0;      ///< after withdrawal, when every node came back within tolerance for good (-1: never)
  bool finite = true;
  double max_kinetic_energy_j = 0.0;
  double max_escape_m = 0.0;        ///< furthest any node went outside the rest bounding box
  std::vector<double> physics_step_us;    ///< every physics step, wall clock
  std::vector<double> collision_step_us;  ///< every collision step, wall clock
  std::uint64_t final_hash = 0;
  TissueFaults faults;
};

/// Runs the protocol on a fresh tissue built from `model`.
IndentationResult run_indentation(const ProstateTissueModel& model, const IndentationOptions& options);

}  // namespace resecto
