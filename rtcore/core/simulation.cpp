// The core's tick: input, kinematics, collision (refit + query) on collision ticks, physics with
// penalty response, metrics and the state hash. Everything is sized in create(); step() only reads
// and writes arrays that already exist.
#include "rtcore/core/simulation.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <span>
#include <thread>
#include <utility>

#include "rtcore/base/flush_denormals.h"
#include "rtcore/base/units.h"
#include "rtcore/core/thread_priority.h"
#include "rtcore/scenes/prostate_tissue.h"
#include "rtcore/base/state_hash.h"

namespace resecto {
namespace {

/// The sheath's and the loop's poses as the state hash reads them, member by member: each pose's
/// rotation column by column, then its translation. Written out so the hash never depends on how
/// RigidPose is laid out in memory (it is the order that layout had, so the hash did not change).
std::array<double, 24> pose_words(const ToolPoses& poses) {
  std::array<double, 24> words{};
  std::size_t w = 0;
  for (const RigidPose* pose : {&poses.sheath, &poses.loop}) {
    for (int c = 0; c < 3; ++c) {
      for (int r = 0; r < 3; ++r) words[w++] = pose->rotation[c][r];
    }
    for (int r = 0; r < 3; ++r) words[w++] = pose->translation[r];
  }
  return words;
}

/// Where the tool waits before the device has reported: far outside the body, touching nothing.
RigidPose withdrawn_pose() {
  RigidPose pose;
  pose.translation = Vec3(0.0, 0.0, -1.0);
  return pose;
}

/// The middle of the loop's wire front, in the tool frame: the point that cuts first.
Vec3 loop_front_point(const TriangleMesh& loop) {
  double front = -1e300;
  for (const Vec3& p : loop.positions) front = std::max(front, p.z);
  Vec3 sum(0.0);
  int count = 0;
  for (const Vec3& p : loop.positions) {
    if (p.z > front - 0.0005) {
      sum += p;
      ++count;
    }
  }
  return sum / static_cast<double>(std::max(count, 1));
}

// The registration places the device in the world: a rotation (orthonormal, not a reflection) and a
// pivot and translation within reach (kRegistrationReachM, as the calibration file's). A header with
// a zero matrix or a pivot at 1e300 m would otherwise replay as a different run, or as NaN.
Status validate_gimbal(const GimbalGeometry& gimbal) {
  const RigidPose& pose = gimbal.device_to_world;
  auto within_reach = [](const Vec3& p) {
    return std::abs(p.x) <= kRegistrationReachM && std::abs(p.y) <= kRegistrationReachM && std::abs(p.z) <= kRegistrationReachM;  // NaN fails
  };
  if (!within_reach(gimbal.pivot_m)) return Error{"gimbal pivot is not a finite point within 1 m of the device's origin on each axis"};
  if (!within_reach(pose.translation)) return Error{"device-to-world translation is not a finite offset within 1 m on each axis"};
  if (!is_proper_rotation(pose.rotation)) {
    return Error{"device-to-world rotation is not a rotation (orthonormal, determinant +1)"};
  }
  return Ok{};
}

}  // namespace

Status SimulationConfig::validate() const {
  if (collision_hz < 10 || collision_hz > 1000) return Error{"collision rate " + std::to_string(collision_hz) + " Hz is outside [10, 1000]"};
  if (physics_per_collision < 1 || physics_per_collision > 64) {
    return Error{"physics substeps " + std::to_string(physics_per_collision) + " per collision step is outside [1, 64]"};
  }
  if (physics_threads < 1 || physics_threads > 2) return Error{"physics threads " + std::to_string(physics_threads) + " is outside [1, 2]"};
  if (prostate_triangles < 200 || prostate_triangles > 1'000'000) {
    return Error{"prostate triangles " + std::to_string(prostate_triangles) + " is outside [200, 1000000]"};
  }
  // A recording's header carries these too: a bound that would ask TetGen for billions of
  // tetrahedra, or buffers of billions of entries, is refused rather than attempted.
  constexpr double kSmallestTetVolumeM3 = 1e-11;  // 0.01 mm^3: a few million tetrahedra in the gland
  if (!(max_tet_volume_m3 == 0.0 || (max_tet_volume_m3 >= kSmallestTetVolumeM3 && max_tet_volume_m3 <= 1.0))) {
    char text[128];
    std::snprintf(text, sizeof text, "tetrahedron volume bound %g m^3 is neither 0 (none) nor within [1e-11, 1]", max_tet_volume_m3);
    return Error{text};
  }
  // The command line's range (--contact-margin-mm): a recording's header must not reach past it.
  if (!(tissue.contact_margin_m >= TissueConfig::kMinContactMarginM && tissue.contact_margin_m <= TissueConfig::kMaxContactMarginM)) {
    char text[128];
    std::snprintf(text, sizeof text, "contact margin %g mm is outside [%g, %g] mm", units::m_to_mm(tissue.contact_margin_m),
                  units::m_to_mm(TissueConfig::kMinContactMarginM), units::m_to_mm(TissueConfig::kMaxContactMarginM));
    return Error{text};
  }
  if (Status registration = validate_gimbal(gimbal); !registration) return registration;
  if (!(tissue.contact_reuse_m >= 0.0 && tissue.contact_reuse_m < tissue.contact_margin_m)) {
    char text[160];
    std::snprintf(text, sizeof text, "contact reuse shift %g mm is outside [0, the contact margin %g mm)", units::m_to_mm(tissue.contact_reuse_m),
                  units::m_to_mm(tissue.contact_margin_m));
    return Error{text};
  }
  constexpr std::int32_t kLargestContactCapacity = 1 << 22;
  const ToolContactCapacity& capacity = tissue.contact_capacity;
  for (const auto& [name, value] : {std::pair{"max_tissue_nodes", capacity.max_tissue_nodes}, std::pair{"max_tool_vertices", capacity.max_tool_vertices},
                                    std::pair{"max_pair_entries", capacity.max_pair_entries}}) {
    if (value < 1 || value > kLargestContactCapacity) {
      return Error{std::string("contact capacity ") + name + " " + std::to_string(value) + " is outside [1, " + std::to_string(kLargestContactCapacity) + "]"};
    }
  }
  return Ok{};
}

// The defaults hold 8640 triangles many times over; the 138,240-triangle demo overflowed the candidate
// nodes at 339 collision steps, dropping contacts nobody saw (a peak force of 69 N instead of 5).
TissueConfig tissue_config_for(const SimulationConfig& config) {
  TissueConfig tissue = config.tissue;
  ToolContactCapacity& room = tissue.contact_capacity;
  const auto triangles = static_cast<std::int64_t>(config.prostate_triangles);
  const auto at_least = [](std::int32_t& value, std::int64_t wanted) {
    value = static_cast<std::int32_t>(std::min<std::int64_t>(std::max<std::int64_t>(value, wanted), std::int64_t{1} << 22));
  };
  at_least(room.max_tissue_nodes, triangles / 2);  // about every surface node: a closed surface has half as many as faces
  at_least(room.max_pair_entries, 4 * triangles);
  return tissue;
}

Result<std::unique_ptr<Simulation>> Simulation::create(const SimulationConfig& config) {
  if (Status valid = config.validate(); !valid) return Error{valid.error()};
  std::unique_ptr<Simulation> sim(new Simulation());
  sim->config_ = config;
  sim->prostate_ = generate_prostate(config.prostate_triangles);
  Result<TetMesh> tetra = tetrahedralize_prostate(sim->prostate_, config.max_tet_volume_m3);
  if (!tetra) return Error{"building the tissue model: " + tetra.error()};
  sim->tetrahedra_ = tetra->tetrahedron_count();
  // Two copies built alike (each with its own reserved room), so either can be the front.
  const ResectoscopeModel tool = generate_resectoscope();
  for (std::unique_ptr<MassSpringTissue>& copy : sim->copies_) {
    copy = std::make_unique<MassSpringTissue>(*tetra, config.parameters, tissue_config_for(config));
    sim->sheath_part_ = copy->tool().add_part(tool.sheath);
    sim->loop_part_ = copy->tool().add_part(tool.loop);
  }
  sim->tissue_ = sim->copies_[0].get();
  sim->lag_log_.reserve(1024, sim->tissue_->node_capacity() / 8, sim->tissue_->topology().tetrahedron_capacity() / 8);
  sim->resection_stats_.perforation_sites.reserve(config.resection.max_perforation_sites);
  for (const Landmark& l : sim->prostate_.landmarks) {
    if (l.name == "verumontanum") sim->verumontanum_z_m_ = l.position.z;
  }
  sim->loop_front_tool_ = loop_front_point(tool.loop);
  ResectionConfig resection = config.resection;
  resection.channel_origin = Vec3(0.0);  // the gland's channel runs along z (prostate.h)
  resection.channel_direction = Vec3(0.0, 0.0, 1.0);
  sim->resection_ = std::make_unique<Resection>(*sim->tissue_, resection);
  sim->wire_loop_ = loop_cutting_arc();
  sim->wire_from_.assign(sim->wire_loop_.size(), Vec3(0.0));
  sim->wire_to_.assign(sim->wire_loop_.size(), Vec3(0.0));
  sim->sweep_ = SweptVolume(sim->wire_loop_.size());
  sim->input_filter_ = JointFilter(config.input_filter);
  const RigidPose away = withdrawn_pose();
  for (std::unique_ptr<MassSpringTissue>& copy : sim->copies_) {
    copy->tool().reset_pose(sim->sheath_part_, away);
    copy->tool().reset_pose(sim->loop_part_, away);
  }
  sim->resection_stats_ = sim->resection_->stats();
  sim->placed_.poses = {withdrawn_pose(), withdrawn_pose()};
  sim->searching_ = sim->published_ = sim->placed_;
  sim->state_hash_ = sim->tissue_->state_hash();
  if (config.physics_threads > 1) {
    sim->physics_helper_ = std::make_unique<LoopHelper>();
    for (std::unique_ptr<MassSpringTissue>& copy : sim->copies_) copy->share_loops_with(sim->physics_helper_.get());
  }
  if (config.collision_thread) {
    Simulation* raw = sim.get();
    sim->collision_thread_ = std::make_unique<JobThread>([raw] { raw->run_collision_job(); });
  }
  return sim;
}

Simulation::~Simulation() {
  if (physics_helper_) physics_helper_->send_home();
}

int default_physics_threads() { return std::thread::hardware_concurrency() >= 2 ? 2 : 1; }

RaisedThreads raise_simulation_threads(Simulation& sim) {
  RaisedThreads raised;
  if (sim.collision_thread()) raised.collision = raise_to_fifo(sim.collision_thread()->native_handle(), kCollisionFifoPriority);
  if (sim.physics_helper()) raised.physics_helper = raise_to_fifo(sim.physics_helper()->native_handle(), kCoreFifoPriority);
  const pthread_t helper = sim.physics_helper() ? sim.physics_helper()->native_handle() : pthread_t{};
  raised.core_cpu = keep_core_apart(pthread_self(), std::span<const pthread_t>(&helper, sim.physics_helper() ? 1 : 0));
  return raised;
}

void Simulation::prepare_for_tick() {
  waited_ = true;
  // Called in ahead of the tick, the helper spins until the loops come: only while the collision
  // job does not need its processor (step() calls it in for the loops alone beside the job).
  if (physics_helper_allowed() && !collision_job_running()) physics_helper_->call_in();
}

void Simulation::place_tool(const TickInput& input) {
  if (!input.tool_present) {
    placed_ = {ToolPoses{withdrawn_pose(), withdrawn_pose()}, false};
  } else if (!placed_.present) {
    // The first placement has nowhere to move from (the tool appears where the device is).
    input_filter_.reset(input.joints);
    placed_ = {resecto::tool_poses(input.joints, config_.gimbal), true};
    placed_joints_ = input.joints;
  } else {
    placed_joints_ = input_filter_.filter(input.joints, config_.tick_s());
    placed_ = {resecto::tool_poses(placed_joints_, config_.gimbal), true};
  }
  tissue_->tool().set_pose(sheath_part_, placed_.poses.sheath);
  tissue_->tool().set_pose(loop_part_, placed_.poses.loop);
  // The energised loop cuts rather than pushes: while it cuts it takes no part in contact. Drawn
  // into the beak it lies inside the sheath, which meets the tissue instead (the back of the retracted
  // wire, a hair inside the sheath's outline, once towed tissue caught behind it out with the sheath).
  cut_pedal_ = input.tool_present && input.cut;
  placed_.loop_in_contact = loop_out_of_sheath() && !loop_cutting();
  tissue_->tool().set_enabled(loop_part_, placed_.loop_in_contact);
}

bool Simulation::loop_out_of_sheath() const {
  // Under half a millimetre of travel the wire is inside the sheath's beak (ResectoscopeShape).
  constexpr double kBeakTravelM = 0.0005;
  return placed_.present && placed_joints_.loop_travel_m >= kBeakTravelM;
}

bool Simulation::loop_cutting() const { return cut_pedal_ && loop_out_of_sheath(); }

void Simulation::prepare_cut() {
  // A wire drawn into the beak with the pedal still down makes one last sweep, from where it cut at
  // the last collision step into the slot: that closes the stroke against the sheath and severs the
  // chip. (Without it the stroke stopped up to a step short of the tip, and what the loop held stayed
  // joined to the gland by a strand the withdrawn sheath then dragged out.)
  const bool closing = cut_pedal_ && wire_from_valid_ && !loop_out_of_sheath();
  cut_job_.cutting = loop_cutting() || closing;
  if (cut_job_.cutting) {
    // The loop's frame is the sheath's moved out by the travel, so the sheath's pose places the
    // wire fully retracted: a closing wire has passed the tip face whatever the filter still lags.
    const RigidPose& wire_pose = closing ? placed_.poses.sheath : placed_.poses.loop;
    for (std::size_t i = 0; i < wire_loop_.size(); ++i) wire_to_[i] = wire_pose.apply_point(wire_loop_[i]);
    sweep_.set(wire_from_valid_ ? wire_from_ : wire_to_, wire_to_, tissue_->parameters().si(TissueParameter::kCuttingRadius));
    std::copy(wire_to_.begin(), wire_to_.end(), wire_from_.begin());
    wire_from_valid_ = !closing;
  } else {
    wire_from_valid_ = false;
  }
  cut_job_.pedal_down = cut_pedal_;
  cut_job_.distal = placed_.present && placed_.poses.loop.apply_point(loop_front_tool_).z < verumontanum_z_m_;
  cut_job_.period_s = config_.tick_s() * config_.physics_per_collision;
  cut_job_.parameters = tissue_->parameters();
}

void Simulation::step(const TickInput& input, std::span<const ParameterCommand> commands, FrameProfiler* profiler) {
  const FlushDenormals flush;  // part of the core's arithmetic: rtcore/base/flush_denormals.h
  const std::uint64_t tick = tick_;
  const bool collision_tick = is_collision_tick(tick);
  // Commands apply in the order they were queued: the console's order, the same on replay. (The
  // caller times latching the input and these together as the input stage.)
  for (const ParameterCommand& command : commands) {
    if (command.apply_tick <= static_cast<std::int64_t>(tick)) tissue_->apply(command);
  }
  {
    RESECTO_PROFILE_STAGE(profiler, Stage::kKinematics, tick);
    place_tool(input);
  }
  if (collision_tick) advance_collision_pipeline(tick, profiler);
  {
    RESECTO_PROFILE_STAGE(profiler, Stage::kPhysics, tick);
    // On a two-core machine the helper and the collision job share the second processor, and the
    // job must finish within its period. Beside the running job the helper is called in for this
    // step's loops alone and sent home after them: spinning at its priority before and between
    // ticks, as it does otherwise, it held the job's processor and the job overran (session 10's
    // and 13's runs), while steps without the helper were the ticks that missed their deadlines.
    // In the second half of the period a job still running (a cut's topology update) has the
    // processor to itself. A batch run's ticks come back to back, so its job would share the
    // processor with the helper from start to end: it has it to itself whenever it runs (the demo at
    // 138,240 triangles: refit + query 6.6-6.8 ms against 12.4-12.8 shared, the run's wall time the
    // same, session 44). Who runs a loop's chunks changes no bit of the state.
    const bool beside_job = collision_job_running();
    if (physics_helper_) {
      const auto per_collision = static_cast<std::uint64_t>(config_.physics_per_collision);
      const bool second_half = 2 * (tick % per_collision) >= per_collision;
      const bool job_needs_processor = beside_job && (!paced_ || second_half);
      const bool allowed = physics_helper_allowed();
      const bool helped = allowed && !job_needs_processor;
      waited_ticks_ = (waited_ticks_ << 1) | (waited_ ? 1u : 0u);
      waited_ = false;
      if (helped && beside_job) physics_helper_->call_in();
      // A step alone for the job still shares its loops, without calling the helper in: that happens
      // between their chunks once the job has ended. At 34,560 triangles and 240 Hz such steps took
      // 3-3.9 ms of the 4.17 ms tick (a cut's topology update running into the period's second
      // half), the ticks the console's runs then missed (session 45).
      tissue_->share_loops_with(allowed ? physics_helper_.get() : nullptr, helped);
      if (!helped) {
        physics_helper_->send_home();  // called in by prepare_for_tick(), not needed after all
        if (allowed) {
          physics_helper_->call_in_when([](const void* job) { return static_cast<const JobThread*>(job)->idle(); }, collision_thread_.get());
        }
      }
    }
    reaction_ = tissue_->physics_step(config_.tick_s());
    // The second processor goes to the collision job: the one running, or the one this tick starts.
    if (physics_helper_ && (beside_job || (collision_tick && collision_thread_))) physics_helper_->send_home();
  }
  {
    RESECTO_PROFILE_STAGE(profiler, Stage::kResponse, tick);
    update_metrics(input, collision_tick);
    if (collision_tick) {
      StateHasher hasher;
      const std::uint64_t tissue_hash = tissue_->state_hash();
      hasher.add(std::span<const std::uint64_t>(&tissue_hash, 1));
      hasher.add(std::span<const std::uint64_t>(&tick, 1));
      const std::array<double, 24> poses = pose_words(placed_.poses);
      hasher.add(std::span<const double>(poses));
      state_hash_ = hasher.value();
    }
  }
  if (collision_tick) start_collision_job();
  ++tick_;
}

// Two copies. Resection's edits cost milliseconds while the loop cuts into fresh tissue (refining it,
// removing, finding hanging pieces and chips), far past a 960 Hz tick's spare time, so they are not
// made on the core's thread. At a collision tick the core hands the wire's sweep to the collision
// step's job, which cuts the copy of the tissue the physics is not stepping (after replaying on it
// the edits the front already holds) at this tick's positions, and then refits and searches that
// copy. At the next collision tick the edited copy adopts the front's motion (positions and
// velocities; its new nodes at their parents' current midpoints) and becomes the front, with the
// candidates found on it. A cut thus reaches the physics one collision period (16.7 ms) after the
// wire swept it, in batch and real-time runs alike; steps that edit nothing keep the front and search it.
void Simulation::advance_collision_pipeline(std::uint64_t tick, FrameProfiler* profiler) {
  if (search_pending_) collect_collision_step(tick, profiler);
  prepare_cut();
  tissue_->begin_collision_step();
  // The candidates found now are used from the next collision tick to the one after it, so the search
  // looks for the tool where it will be in the middle of that window, 1.5 collision periods ahead,
  // extrapolating the (smoothed) joints' motion of the last tick. The margin then has to cover only
  // half the window's motion and the motion's change of speed: about twice the speed a search at the
  // current pose covers. (The tissue's own motion is slower and left to the margin.)
  searching_ = placed_;
  if (config_.predict_search_pose && placed_.present && last_search_present_) {
    const DeviceJoints& now = placed_joints_;
    const DeviceJoints& before = last_search_joints_;
    const auto extrapolated = [&](double lead) {
      DeviceJoints ahead;
      ahead.yaw_rad = now.yaw_rad + lead * (now.yaw_rad - before.yaw_rad);
      ahead.pitch_rad = now.pitch_rad + lead * (now.pitch_rad - before.pitch_rad);
      ahead.roll_rad = now.roll_rad + lead * (now.roll_rad - before.roll_rad);
      ahead.insertion_m = now.insertion_m + lead * (now.insertion_m - before.insertion_m);
      ahead.loop_travel_m = now.loop_travel_m + lead * (now.loop_travel_m - before.loop_travel_m);
      return resecto::tool_poses(ahead, config_.gimbal);
    };
    searching_.poses = extrapolated(1.5);
    tissue_->tool().set_query_pose(sheath_part_, searching_.poses.sheath);
    tissue_->tool().set_query_pose(loop_part_, searching_.poses.loop);
    // The candidates' first physics step is at the next collision tick, one period ahead: the search
    // certifies the points' clearance where the tool should be then, so that step skips most of them.
    const ToolPoses at_publish = extrapolated(1.0);
    tissue_->tool().set_certify_pose(sheath_part_, at_publish.sheath);
    tissue_->tool().set_certify_pose(loop_part_, at_publish.loop);
  }
  last_search_joints_ = placed_joints_;
  last_search_present_ = placed_.present;
  search_timing_.tick = tick;
  search_pending_ = true;
  copies_[static_cast<std::size_t>(1 - front_)]->tool().copy_query_state(tissue_->tool());
}

// The job reads only what the collision tick fixed before its physics step (the positions taken for
// the search, the latched poses, the sweep, the other copy), so where it starts changes no result.
// It starts after the tick's physics and response: the collision tick, which also adopts, publishes
// and hashes, then runs with the machine to itself, and the job's work falls on the plain ticks
// after it, which have the room.
void Simulation::start_collision_job() {
  if (collision_thread_) {
    collision_thread_->launch();
  } else {
    run_collision_job();
  }
}

void Simulation::collect_collision_step(std::uint64_t tick, FrameProfiler* profiler) {
  {
    // Normally the job finished long ago and this costs nothing; in batch mode, or when the machine
    // is overloaded, the core waits here rather than go on with other candidates.
    RESECTO_PROFILE_STAGE(profiler, Stage::kCollisionWait, tick);
    if (collision_thread_) collision_thread_->wait();
  }
  if (job_edited_) {
    RESECTO_PROFILE_STAGE(profiler, Stage::kAdopt, tick);
    MassSpringTissue& edited = *copies_[static_cast<std::size_t>(1 - front_)];
    edited.adopt_motion(*tissue_, lag_log_.midpoint_parents(), lag_log_.orphans());
    front_ = 1 - front_;
    tissue_ = &edited;
  }
  if (job_reused_) {
    ++contact_searches_reused_;  // the front's candidates, and the pose they were searched at, stay
  } else {
    tissue_->end_collision_step();
    published_ = searching_;
    ++contact_searches_;
  }
  last_cut_ = job_cut_;
  resection_stats_ = resection_->stats();
  search_pending_ = false;
  if (profiler) {
    profiler->record(Stage::kTopology, search_timing_.tick, search_timing_.begin_ns, search_timing_.topology_end_ns);
    profiler->record(Stage::kRefit, search_timing_.tick, search_timing_.topology_end_ns, search_timing_.refit_end_ns);
    profiler->record(Stage::kQuery, search_timing_.tick, search_timing_.refit_end_ns, search_timing_.query_end_ns);
  }
}

void Simulation::settle() {
  if (search_pending_) collect_collision_step(tick_, nullptr);
  update_resection_metrics();
}

void Simulation::run_collision_job() {
  search_timing_.begin_ns = FrameProfiler::now_ns();
  MassSpringTissue& front = *tissue_;
  MassSpringTissue& other = *copies_[static_cast<std::size_t>(1 - front_)];
  const bool replays = !lag_log_.empty();
  if (replays) {
    other.replay(lag_log_);
    lag_log_.clear();
  }
  other.match_parameters(cut_job_.parameters);
  // The front's positions at the collision tick (begin_collision_step took them for the search).
  const std::span<const Vec3> positions(front.surface().positions.data(), front.node_count());
  if (cut_job_.cutting) other.set_positions(positions);
  other.set_edit_log(&lag_log_);
  resection_->bind(other);
  job_cut_ = resection_->step(cut_job_.cutting ? &sweep_ : nullptr, cut_job_.pedal_down, cut_job_.distal, cut_job_.period_s);
  other.set_edit_log(nullptr);
  job_edited_ = !lag_log_.empty();
  if (job_edited_ && !cut_job_.cutting) other.set_positions(positions);  // a compaction adds no node
  other.refresh_mesh_surface();  // for the snapshot of the tick that takes this copy in (fill_snapshot)
  other.refresh_stepped_nodes();  // here rather than in the physics step that takes it in
  search_timing_.topology_end_ns = FrameProfiler::now_ns();
  // Temporal coherence: while the tool and the tissue have barely moved from where the front's
  // candidates were searched, they serve the next window too, and the step skips its refit and
  // search (most of a collision step's cost). A cut always searches: its faces are new.
  const bool quiet = !replays && !job_edited_;
  job_reused_ = !job_edited_ && front.contact_candidates_still_serve();
  if (job_reused_) {
    if (quiet) other.rebuild_surface_tree_if_due();
    search_timing_.refit_end_ns = search_timing_.query_end_ns = FrameProfiler::now_ns();
    return;
  }
  MassSpringTissue& searched = job_edited_ ? other : front;
  if (job_edited_) other.take_search_positions();
  // A decayed tree's rebuild costs as much as a cut's edits (about 5 ms of processor at 8640
  // triangles); both in one job overran the collision period and held the core up, and so did a
  // whole rebuild beside a quiet job's search. A job that edits or replays rebuilds only an overdue
  // tree, whole; a quiet one takes a staged rebuild of the searched copy's tree, or else of the other
  // copy's, a few levels further (MassSpringTissue::kStagedRebuildLevels), so both are sound again
  // within a few collision steps after a stroke ends.
  const bool rebuilt = searched.refit_surface_tree(quiet ? MassSpringTissue::TreeRebuild::kWhenDue : MassSpringTissue::TreeRebuild::kOnlyWhenOverdue);
  if (quiet && !rebuilt) other.rebuild_surface_tree_if_due();
  search_timing_.refit_end_ns = FrameProfiler::now_ns();
  searched.search_contact_candidates();
  search_timing_.query_end_ns = FrameProfiler::now_ns();
}

void Simulation::update_metrics(const TickInput& input, bool collision_tick) {
  const double h = config_.tick_s();
  const bool contact = tissue_->tool().stats().penetrating > 0;
  const double force = length(reaction_.force_n);
  const bool cutting = input.tool_present && input.cut;
  metrics_.peak_reaction_force_n = std::max(metrics_.peak_reaction_force_n, force);
  step_peak_force_n_ = step_peak_restarts_ ? force : std::max(step_peak_force_n_, force);
  step_peak_restarts_ = collision_tick;
  if (contact) {
    metrics_.contact_time_s = static_cast<double>(++contact_ticks_) * h;
    contact_force_sum_n_ += force;
    metrics_.mean_contact_force_n = contact_force_sum_n_ / static_cast<double>(contact_ticks_);
  }
  if (cutting) {
    metrics_.cut_pedal_time_s += h;
    if (contact) metrics_.cut_in_contact_time_s += h;
  }
  if (placed_.present) metrics_.max_insertion_mm = std::max(metrics_.max_insertion_mm, units::m_to_mm(placed_joints_.insertion_m));
  // The candidates in use were searched with the tool where published_ has it; the sheath's tip
  // and the loop's front move furthest. The loop counts only while it takes part in contact, now and
  // at that search, as the reuse of candidates reckons it: a cutting loop has none to outrun, and one
  // just back in contact is searched at the next collision step (audit 9: a loop drawn back through
  // a stroke was counted as outrunning candidates the run had rightly kept for the sheath).
  const ToolPoses& now = placed_.poses;
  const ToolPoses& searched = published_.poses;
  const double loop_travel_m = placed_.loop_in_contact && published_.loop_in_contact
                                   ? length(now.loop.apply_point(loop_front_tool_) - searched.loop.apply_point(loop_front_tool_))
                                   : 0.0;
  const double travel_m = std::max(length(now.sheath.translation - searched.sheath.translation), loop_travel_m);
  if (placed_.present && published_.present) {
    metrics_.max_tool_travel_since_search_mm = std::max(metrics_.max_tool_travel_since_search_mm, units::m_to_mm(travel_m));
    if (travel_m > tissue_->tool().margin_m()) ++metrics_.contact_margin_exceeded_ticks;
  }
  if (!collision_tick) return;
  // The costlier measures once per collision step.
  metrics_.max_tissue_displacement_mm = std::max(metrics_.max_tissue_displacement_mm, units::m_to_mm(tissue_->max_displacement_m()));
  // Only a loop out of the sheath can cut: a pedal pressed with the loop retracted risks nothing (audit 9).
  if (loop_cutting()) {
    const double margin_m = placed_.poses.loop.apply_point(loop_front_tool_).z - verumontanum_z_m_;
    const double margin_mm = units::m_to_mm(margin_m);
    metrics_.distal_margin_mm = std::min(metrics_.distal_margin_mm.value_or(margin_mm), margin_mm);
    if (margin_m < 0.0) ++metrics_.verumontanum_violations;
  }
  update_resection_metrics();
}

void Simulation::update_resection_metrics() {
  const ResectionStats& cut = resection_stats_;
  const double grams_per_m3 = tissue_->parameters().si(TissueParameter::kDensity) * 1000.0;
  constexpr auto kCapsule = static_cast<std::size_t>(TissueRegion::kCapsule), kAdenoma = static_cast<std::size_t>(TissueRegion::kAdenoma);
  metrics_.initial_tissue_g = grams_per_m3 * (cut.initial_m3[kCapsule] + cut.initial_m3[kAdenoma]);
  metrics_.resected_adenoma_g = grams_per_m3 * cut.removed_m3[kAdenoma];
  metrics_.resected_capsule_g = grams_per_m3 * cut.removed_m3[kCapsule];
  metrics_.resected_total_g = metrics_.resected_adenoma_g + metrics_.resected_capsule_g;
  metrics_.remaining_tissue_g = metrics_.initial_tissue_g - metrics_.resected_total_g;
  metrics_.remaining_adenoma_fraction =
      cut.initial_m3[kAdenoma] > 0.0 ? (cut.initial_m3[kAdenoma] - cut.removed_m3[kAdenoma]) / cut.initial_m3[kAdenoma] : 1.0;
  metrics_.chips = static_cast<std::uint64_t>(cut.chips);
  metrics_.chips_g = grams_per_m3 * (cut.chip_m3[kCapsule] + cut.chip_m3[kAdenoma]);
  metrics_.cuts = static_cast<std::uint64_t>(cut.cuts);
  metrics_.perforations = static_cast<std::uint64_t>(cut.perforations);
  metrics_.sphincter_zone_violations = static_cast<std::uint64_t>(cut.sphincter_zone_violations);
  metrics_.sphincter_zone_cut_s = cut.sphincter_zone_cut_s;
  metrics_.loop_on_idle_s = cut.loop_on_idle_s;
  metrics_.refined_tetrahedra = static_cast<std::uint64_t>(cut.refined_tetrahedra);
  metrics_.topology_refusals = static_cast<std::uint64_t>(cut.refusals + tissue_->faults().topology_capacity_refusals);
  metrics_.non_finite_steps = static_cast<std::uint64_t>(tissue_->faults().non_finite_steps);
  metrics_.contact_overflows = static_cast<std::uint64_t>(tissue_->faults().contact_overflows);
}

void Simulation::fill_snapshot(SimulationSnapshot& snapshot) const {
  snapshot.tick = tick_;
  snapshot.state_hash = state_hash_;
  snapshot.tool = placed_.poses;
  snapshot.reaction = reaction_;
  snapshot.penetrating_points = tissue_->tool().stats().penetrating;
  const std::size_t nodes = std::min(snapshot.node_positions.size(), tissue_->node_count());
  tissue_->copy_mesh_positions(std::span<Vec3>(snapshot.node_positions.data(), nodes));
  snapshot.node_count = static_cast<std::uint32_t>(nodes);
  // The connectivity changes only with topology_version (the two copies of the tissue count their
  // edits alike): a slot that already holds this version's faces keeps them, which spares a pass over
  // the surface at most collision ticks. The faces come listed in mesh ids with their regions by the
  // collision job, which relists the copy it edited (MassSpringTissue::refresh_mesh_surface); the
  // core only copies them, at the tick that takes the edited copy in and has the least room.
  if (snapshot.topology_version != tissue_->topology_version()) {
    const MassSpringTissue::MeshSurface& listed = tissue_->mesh_surface();
    std::size_t count = 0;
    if (listed.version == tissue_->topology_version()) {
      count = std::min({listed.count, snapshot.surface_triangles.size(), snapshot.surface_regions.size()});
      std::copy_n(listed.triangles.begin(), count, snapshot.surface_triangles.begin());
      std::copy_n(listed.regions.begin(), count, snapshot.surface_regions.begin());
    } else {  // edited outside a collision job (a test, a tool)
      count = tissue_->list_mesh_surface(snapshot.surface_triangles, snapshot.surface_regions);
    }
    snapshot.surface_triangle_count = static_cast<std::uint32_t>(count);
    snapshot.topology_version = tissue_->topology_version();
  }
  snapshot.metrics = metrics_;
}

SimulationSnapshot Simulation::make_snapshot() const {
  SimulationSnapshot snapshot;
  snapshot.node_positions.resize(tissue_->node_capacity());
  snapshot.surface_triangles.resize(tissue_->surface_face_capacity());
  snapshot.surface_regions.resize(tissue_->surface_face_capacity());
  snapshot.topology_version = ~std::uint64_t{0};  // no faces yet: the fill copies them
  fill_snapshot(snapshot);
  return snapshot;
}

std::array<double, kStageCount> default_stage_budgets_us(const SimulationConfig& config) {
  const double tick_us = config.tick_s() * 1e6;
  std::array<double, kStageCount> budgets{};
  const double collision_period_us = tick_us * config.physics_per_collision;
  // Shares of one tick on the core's thread: physics every tick; the rest is small. The refit and
  // query run on the collision thread and share one collision period, with headroom because that
  // thread shares the machine's cores with the core, the device link and the console.
  budgets[static_cast<int>(Stage::kInput)] = 0.05 * tick_us;
  budgets[static_cast<int>(Stage::kKinematics)] = 0.02 * tick_us;
  budgets[static_cast<int>(Stage::kCollisionWait)] = 0.02 * tick_us;
  // Resection's edits run on the collision thread before the refit and query, sharing its period;
  // the core's part is the edited copy adopting the front's motion (a copy of the node arrays).
  budgets[static_cast<int>(Stage::kAdopt)] = 0.10 * tick_us;
  budgets[static_cast<int>(Stage::kTopology)] = 0.30 * collision_period_us;
  budgets[static_cast<int>(Stage::kPhysics)] = 0.40 * tick_us;
  budgets[static_cast<int>(Stage::kRefit)] = 0.15 * collision_period_us;
  budgets[static_cast<int>(Stage::kQuery)] = 0.45 * collision_period_us;
  budgets[static_cast<int>(Stage::kResponse)] = 0.05 * tick_us;
  budgets[static_cast<int>(Stage::kPublish)] = 0.05 * tick_us;
  budgets[static_cast<int>(Stage::kTick)] = tick_us;
  return budgets;
}

}  // namespace resecto
