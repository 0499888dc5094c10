// The indentation protocol. Wall-clock timing happens here, around the core's steps, never inside.
#include "rtcore/scenes/indentation.h"

#include <algorithm>
#include <chrono>
#include <cmath>

namespace resecto {

RigidPose indentation_loop_pose(const ProstateModel& anatomy, const TriangleMesh& loop, double depth_m) {
  RigidPose pose;
  // Roll +90 degrees about the sheath axis: the wire's -y side turns to +x, the left lobe.
  pose.rotation[0] = Vec3(0.0, 1.0, 0.0);  // columns: x -> +y, y -> -x
  pose.rotation[1] = Vec3(-1.0, 0.0, 0.0);
  Vec3 outermost(-1e300, 0.0, 0.0);
  for (const Vec3& p : loop.positions) {
    const Vec3 rolled = pose.apply_point(p);
    if (rolled.x > outermost.x) outermost = rolled;
  }
  Vec3 crest(0.0);
  for (const Landmark& landmark : anatomy.landmarks) {
    if (landmark.name == "lateral_lobe_left") crest = landmark.position;
  }
  pose.translation = {crest.x - outermost.x + depth_m, 0.0, crest.z - outermost.z};
  return pose;
}

IndentationResult run_indentation(const ProstateTissueModel& model, const IndentationOptions& options) {
  using Clock = std::chrono::steady_clock;
  MassSpringTissue tissue(model.mesh, options.parameters, options.config);
  const TriangleMesh& loop = model.loop;
  const int loop_part = tissue.tool().add_part(loop);

  IndentationResult result;
  result.nodes = tissue.node_count();
  result.tetrahedra = model.mesh.tetrahedron_count();
  result.springs = tissue.network().spring_count();
  result.surface_triangles = tissue.surface().triangle_count();

  const double h_s = 1.0 / (options.collision_hz * options.substeps);
  const double press_end = options.press_s, hold_end = press_end + options.hold_s;
  const double withdraw_end = hold_end + options.withdraw_s, end = withdraw_end + options.relax_s;
  // Ticks are integers; time is tick * h, never accumulated.
  const auto ticks = static_cast<std::int64_t>(std::llround(end / h_s));
  auto depth_at = [&](double t) {
    if (t <= press_end) return options.depth_m * t / options.press_s;
    if (t <= hold_end) return options.depth_m;
    if (t <= withdraw_end) {
      const double s = (t - hold_end) / options.withdraw_s;
      return options.depth_m + s * (-options.withdraw_clearance_m - options.depth_m);
    }
    return -options.withdraw_clearance_m;
  };

  Aabb box{Vec3(1e300), Vec3(-1e300)};
  for (const Vec3& p : tissue.rest_positions()) {
    box.min = glm::min(box.min, p);
    box.max = glm::max(box.max, p);
  }
  result.physics_step_us.reserve(static_cast<std::size_t>(ticks));
  result.collision_step_us.reserve(static_cast<std::size_t>(ticks / options.substeps + 1));
  result.curve.reserve(static_cast<std::size_t>(ticks / options.substeps + 1));

  tissue.tool().reset_pose(loop_part, indentation_loop_pose(model.anatomy, loop, depth_at(0.0)));
  double last_unsettled_s = withdraw_end;
  for (std::int64_t tick = 0; tick < ticks; ++tick) {
    const double t = static_cast<double>(tick + 1) * h_s;  // the pose this step moves toward
    if (tick % options.substeps == 0) {
      const auto start = Clock::now();
      tissue.collision_step();
      result.collision_step_us.push_back(std::chrono::duration<double, std::micro>(Clock::now() - start).count());
      if (options.on_collision_step) options.on_collision_step(tick / options.substeps, tissue.state_hash());
    }
    tissue.tool().set_pose(loop_part, indentation_loop_pose(model.anatomy, loop, depth_at(t)));
    const auto start = Clock::now();
    const ToolReaction reaction = tissue.physics_step(h_s);
    result.physics_step_us.push_back(std::chrono::duration<double, std::micro>(Clock::now() - start).count());

    result.max_kinetic_energy_j = std::max(result.max_kinetic_energy_j, tissue.kinetic_energy_j());
    if ((tick + 1) % options.substeps == 0) {
      const double push = -reaction.force_n.x;  // the loop presses along +x
      result.curve.push_back({t, depth_at(t), push});
      result.peak_force_n = std::max(result.peak_force_n, push);
      const double displacement = tissue.max_displacement_m();
      result.max_displacement_m = std::max(result.max_displacement_m, displacement);
      if (t > withdraw_end && displacement > options.rest_tolerance_m) {
        last_unsettled_s = t;
      }
      for (const Vec3& p : tissue.positions()) {
        const Vec3 outside = glm::max(box.min - p, p - box.max);
        result.max_escape_m = std::max(result.max_escape_m, std::max({outside.x, outside.y, outside.z}));
      }
    }
  }
  result.residual_m = tissue.max_displacement_m();
  result.settle_time_s = result.residual_m <= options.rest_tolerance_m ? last_unsettled_s - withdraw_end : -1.0;
  result.faults = tissue.faults();
  result.finite = tissue.faults().non_finite_steps == 0 && std::isfinite(result.max_kinetic_energy_j);
  result.final_hash = tissue.state_hash();
  return result;
}

}  // namespace resecto
