// Simulation: the deterministic core, state(k+1) = step(state(k), input(k), commands(k)). Ticks are
// physics steps (960 Hz by default); every `physics_per_collision` ticks a collision step refits the
// tissue's sphere tree and finds the tool's contact candidates (60 Hz; or keeps the candidates in use
// while the tool and tissue have barely moved since they were searched), and the state hash is taken.
// The refit and search of collision step n run alongside the physics ticks up to step n+1, whose tick
// publishes their candidates: a fixed one-step pipeline, so the result never depends on when the
// search finishes, or on which thread it ran. Wall-clock time never enters: the profiler only watches.
#pragma once

#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <vector>

#include "rtcore/anatomy/prostate.h"
#include "rtcore/anatomy/resectoscope.h"
#include "rtcore/base/result.h"
#include "rtcore/concurrency/job_thread.h"
#include "rtcore/concurrency/loop_helper.h"
#include "rtcore/core/joint_filter.h"
#include "rtcore/core/profiler.h"
#include "rtcore/core/tick_input.h"
#include "rtcore/kinematics/tool_kinematics.h"
#include "rtcore/resection/resection.h"
#include "rtcore/tissue/mass_spring.h"
#include "rtcore/tissue/tissue_parameters.h"

namespace resecto {

/// What a simulation is built from; fixed for its lifetime.
struct SimulationConfig {
  int prostate_triangles = 8640;
  int collision_hz = 60;
  int physics_per_collision = 16;  ///< physics ticks per collision step: 16 gives 960 Hz
  /// Runs each collision step's refit and search on a thread of its own, concurrently with the
  /// physics ticks that follow it. The results are the same either way (see Simulation::step).
  bool collision_thread = true;
  /// Threads that share each physics step's spring and node loops: 1 (the core alone) or 2 (the core
  /// and a helper). The results are the same bit for bit either way.
  int physics_threads = 1;
  TissueParameters parameters;     ///< initial values; later changes come as commands
  GimbalGeometry gimbal;
  double max_tet_volume_m3 = 0.0;  ///< TetGen -a bound for the tissue model; 0 = unbounded
  JointFilterSettings input_filter;  ///< smoothing of the device's readings (joint_filter.h)
  /// Searches for contact candidates around the tool's extrapolated pose in the middle of the
  /// window the candidates serve, rather than where it is at the search (Simulation::step).
  bool predict_search_pose = true;
  /// The tissue's fixed choices: integrator, contact margin and capacities, clearance certificates.
  TissueConfig tissue;
  /// Resection's choices (refinement on or off, target edge); its channel axis is the gland's.
  ResectionConfig resection;

  double tick_s() const { return 1.0 / (static_cast<double>(collision_hz) * physics_per_collision); }
  /// Whether a run of `seconds` (rounded to whole ticks) holds at least one collision step: a shorter
  /// one would report and record nothing a replay or a score can use.
  bool holds_a_collision_step(double seconds) const { return std::llround(seconds / tick_s()) >= physics_per_collision; }
  /// The tick rates as a user would write them, or an error naming the bad value.
  Status validate() const;
};

/// A trainee's procedure in numbers, accumulated every tick.
struct ProcedureMetrics {
  double contact_time_s = 0.0;             ///< time any tool part pressed into tissue
  double cut_pedal_time_s = 0.0;
  /// Pedal down while any tool part pressed tissue: the energised loop cuts and takes no part in
  /// contact, so this is the sheath (or the loop retracted against the beak) pressing while the pedal
  /// is down, not time spent cutting tissue (loop_on_idle_s in the resection metrics is the pedal down
  /// with nothing cut).
  double cut_in_contact_time_s = 0.0;
  double peak_reaction_force_n = 0.0;      ///< largest force of the tissue on the tool
  double mean_contact_force_n = 0.0;       ///< over the ticks in contact
  double max_tissue_displacement_mm = 0.0;
  double max_insertion_mm = 0.0;           ///< deepest the sheath tip went past the pivot
  /// Least loop-to-verumontanum distance (along z) while cutting; + is proximal (safe). None until the pedal cuts.
  std::optional<double> distal_margin_mm;
  std::uint64_t verumontanum_violations = 0;  ///< collision steps cutting distal to the verumontanum
  std::uint64_t non_finite_steps = 0;
  std::uint64_t contact_overflows = 0;
  /// Ticks at which the tool had moved further than the contact margin from where the candidates in
  /// use were searched: motion faster than contact can follow (margin / two collision periods).
  std::uint64_t contact_margin_exceeded_ticks = 0;
  double max_tool_travel_since_search_mm = 0.0;  ///< the largest such travel
  // Resection (rtcore/resection): grams at the live density, from rest volumes.
  double initial_tissue_g = 0.0;
  double remaining_tissue_g = 0.0;
  double resected_adenoma_g = 0.0;   ///< everything that left the gland: cut by the loop, hanging, chips
  double resected_capsule_g = 0.0;
  double resected_total_g = 0.0;
  double remaining_adenoma_fraction = 1.0;
  std::uint64_t chips = 0;
  double chips_g = 0.0;
  std::uint64_t cuts = 0;                       ///< strokes (pedal presses) that removed tissue
  std::uint64_t perforations = 0;               ///< strokes that opened the gland's outer surface
  std::uint64_t sphincter_zone_violations = 0;  ///< strokes that removed tissue distal to the verumontanum
  double sphincter_zone_cut_s = 0.0;
  double loop_on_idle_s = 0.0;                  ///< pedal down and nothing removed
  std::uint64_t refined_tetrahedra = 0;
  std::uint64_t topology_refusals = 0;          ///< edits refused for want of reserved capacity
};

/// Calls `visit(field)` on every field of `m` in declaration order (the order recordings store them,
/// one 8-byte word each): a double, a std::uint64_t or the one std::optional<double>.
template <class Metrics, class Visit>
constexpr void for_each_metric(Metrics& m, Visit&& visit) {
  visit(m.contact_time_s);
  visit(m.cut_pedal_time_s);
  visit(m.cut_in_contact_time_s);
  visit(m.peak_reaction_force_n);
  visit(m.mean_contact_force_n);
  visit(m.max_tissue_displacement_mm);
  visit(m.max_insertion_mm);
  visit(m.distal_margin_mm);
  visit(m.verumontanum_violations);
  visit(m.non_finite_steps);
  visit(m.contact_overflows);
  visit(m.contact_margin_exceeded_ticks);
  visit(m.max_tool_travel_since_search_mm);
  visit(m.initial_tissue_g);
  visit(m.remaining_tissue_g);
  visit(m.resected_adenoma_g);
  visit(m.resected_capsule_g);
  visit(m.resected_total_g);
  visit(m.remaining_adenoma_fraction);
  visit(m.chips);
  visit(m.chips_g);
  visit(m.cuts);
  visit(m.perforations);
  visit(m.sphincter_zone_violations);
  visit(m.sphincter_zone_cut_s);
  visit(m.loop_on_idle_s);
  visit(m.refined_tetrahedra);
  visit(m.topology_refusals);
}
/// How many fields for_each_metric visits.
constexpr std::size_t metric_field_count() {
  ProcedureMetrics m;
  std::size_t n = 0;
  for_each_metric(m, [&n](auto&) { ++n; });
  return n;
}
// A field added to ProcedureMetrics but not to for_each_metric fails here.
static_assert(sizeof(ProcedureMetrics) == 8 * (metric_field_count() - 1) + sizeof(std::optional<double>),
              "for_each_metric must visit every field of ProcedureMetrics");

/// The tissue configuration a simulation builds its tissue with: `config.tissue` with room for the
/// contact candidates of its gland, since a finer surface has proportionally more nodes and faces
/// within the margin of the tool (about every surface node, half the faces; four pairs per face),
/// never less than the configured room nor more than validate() allows.
TissueConfig tissue_config_for(const SimulationConfig& config);

/// What the core publishes for the console and recorder (taken at collision steps).
struct SimulationSnapshot {
  std::uint64_t tick = 0;
  std::uint64_t state_hash = 0;
  ToolPoses tool;
  ToolReaction reaction;
  std::int32_t penetrating_points = 0;
  /// Positions of the tissue's nodes by mesh id, valid in [0, node_count): the surface's vertices
  /// and the inner nodes resection may expose. Sized once by make_snapshot(), never reallocated.
  std::vector<Vec3> node_positions;
  std::uint32_t node_count = 0;
  /// The tissue's current boundary over node ids (outward), valid in [0, surface_triangle_count).
  /// Sized once to the surface's capacity.
  std::vector<Triangle> surface_triangles;
  std::uint32_t surface_triangle_count = 0;
  /// Changes whenever surface_triangles change; equal versions mean equal connectivity, so a reader
  /// copies or encodes the connectivity only when it moved.
  std::uint64_t topology_version = 0;
  /// Region of the tetrahedron behind each surface triangle, valid in [0, surface_triangle_count).
  std::vector<TissueRegion> surface_regions;
  ProcedureMetrics metrics;
};

class Simulation {
 public:
  /// Builds the gland, its tetrahedral model, the tissue and the tool. Allocates everything here.
  static Result<std::unique_ptr<Simulation>> create(const SimulationConfig& config);
  /// Sends the physics helper home first: called in by prepare_for_tick() for a tick that never
  /// came, it would spin at the core's priority while the collision thread waits to be joined.
  ~Simulation();

  /// Runs tick `tick()`: applies the commands stamped for it, places the tool; on collision ticks
  /// takes in the previous collision step (its edited copy of the tissue becomes the front, its
  /// candidates are published) and starts this one's cut, refit and search (on the collision
  /// thread, or here); steps the tissue; on collision ticks hashes. Allocates nothing,
  /// locks nothing, does no I/O.
  void step(const TickInput& input, std::span<const ParameterCommand> commands, FrameProfiler* profiler = nullptr);

  std::uint64_t tick() const { return tick_; }
  bool is_collision_tick(std::uint64_t tick) const { return tick % static_cast<std::uint64_t>(config_.physics_per_collision) == 0; }
  /// The hash taken at the last collision step.
  std::uint64_t state_hash() const { return state_hash_; }
  const ProcedureMetrics& metrics() const { return metrics_; }
  /// The copy of the tissue the physics steps (the front; see "Two copies" in simulation.cpp).
  const MassSpringTissue& tissue() const { return *tissue_; }
  /// Resection runs in the collision step's job: read it between steps of a run without a collision
  /// thread, or after settle().
  const Resection& resection() const { return *resection_; }
  /// Sphere-tree rebuilds of both copies of the tissue (each rebuilds its own when edits decay it).
  /// Like resection(): between steps of a run without a collision thread, or after settle().
  std::int64_t surface_tree_rebuilds() const { return copies_[0]->surface_tree_rebuilds() + copies_[1]->surface_tree_rebuilds(); }
  /// Resection's totals as of the last collected collision step: they account for exactly the edits
  /// tissue() holds, whichever thread cut (a copy taken at each collection).
  const ResectionStats& resection_stats() const { return resection_stats_; }
  /// What the last collected collision step's topology update removed and refined.
  const ResectionStep& last_resection_step() const { return last_cut_; }
  /// Collected collision steps that refitted and searched, and those that kept the candidates in use
  /// because the tool and tissue had barely moved since they were searched (TissueConfig::contact_reuse_m).
  std::uint64_t contact_searches() const { return contact_searches_; }
  std::uint64_t contact_searches_reused() const { return contact_searches_reused_; }
  /// Waits for the collision step in flight and takes in its result (the edited copy becomes the
  /// front, the candidates are published, the resection metrics renewed), so that tissue(),
  /// resection() and metrics() agree: call once a run ends, before reading the tissue it left.
  /// Stepping on afterwards starts the next collision step at the next collision tick as usual.
  void settle();
  const ProstateModel& prostate() const { return prostate_; }
  const SimulationConfig& config() const { return config_; }
  const ToolPoses& tool_poses() const { return placed_.poses; }
  const ToolReaction& reaction() const { return reaction_; }
  /// The largest reaction force over the ticks after the previous collision tick, the latest
  /// included: read right after a collision tick, over that collision step's ticks. A plot sampled
  /// once per collision step shows every spike between its samples with it (reaction() is the last
  /// tick's alone). Derived, not part of the state.
  double largest_reaction_force_n_of_step() const { return step_peak_force_n_; }
  std::size_t tetrahedron_count() const { return tetrahedra_; }
  /// The thread that runs the collision refit and search; null when they run inline.
  JobThread* collision_thread() { return collision_thread_.get(); }
  /// Real time, about a spin ahead of each tick: calls in the physics helper if the coming tick's
  /// physics will share its loops with it, so the helper is running when they begin (a sleeping
  /// helper on an idle virtual CPU takes tens of microseconds to wake). Changes no state. Called
  /// only when the core waits for a tick: a paced core that waits for fewer than half of its ticks
  /// is overloaded, and gives up the helper until it keeps time again.
  void prepare_for_tick();
  /// The ticks are paced in real time (prepare_for_tick() is called whenever the core waits for one),
  /// so the helper's use can follow whether the core keeps time. Changes no state.
  void set_paced() { paced_ = true; }
  /// The physics step's helper thread (physics_threads = 2), else nullptr.
  LoopHelper* physics_helper() { return physics_helper_.get(); }
  const LoopHelper* physics_helper() const { return physics_helper_.get(); }

  /// Copies the publishable state into `snapshot` (whose surface array is sized by make_snapshot()).
  void fill_snapshot(SimulationSnapshot& snapshot) const;
  SimulationSnapshot make_snapshot() const;

 private:
  Simulation() = default;
  void place_tool(const TickInput& input);
  void update_metrics(const TickInput& input, bool collision_tick);
  /// Takes in the running collision step (collect_collision_step) and prepares the next, which
  /// start_collision_job() starts at the end of the tick.
  void advance_collision_pipeline(std::uint64_t tick, FrameProfiler* profiler);
  /// Launches the prepared job on the collision thread, or runs it here without one.
  void start_collision_job();
  /// Waits for the collision step's job; if it edited the other copy, that copy adopts the front's
  /// motion and becomes the front; publishes its candidates.
  void collect_collision_step(std::uint64_t tick, FrameProfiler* profiler);
  /// The collision step's job, on whichever thread runs it: the other copy catches up on the front's
  /// edits and is cut; then the copy that will be the front is refitted and searched. Timed.
  void run_collision_job();
  /// Resection's part of a collision tick on the core: the wire's sweep since the last one, for the job.
  void prepare_cut();
  /// The resection part of the metrics, from the last collected step's statistics.
  void update_resection_metrics();
  /// Whether the tool is placed with the loop's wire out of the sheath's beak.
  bool loop_out_of_sheath() const;
  /// Whether the loop cuts this tick: pedal down and the wire out of the sheath's beak.
  bool loop_cutting() const;

  SimulationConfig config_;
  ProstateModel prostate_;
  // Two copies of the tissue: the physics steps *tissue_ (the front) while a collision step's job
  // edits the other; lag_log_ holds the edits the copy behind has not made yet.
  std::array<std::unique_ptr<MassSpringTissue>, 2> copies_;
  int front_ = 0;
  MassSpringTissue* tissue_ = nullptr;
  TissueEditLog lag_log_;
  std::unique_ptr<Resection> resection_;
  /// What the core hands a collision step's job (written at launch, read by the job).
  struct CutJob {
    bool cutting = false;  // sweep_ holds the wire's path
    bool pedal_down = false;
    bool distal = false;
    double period_s = 0.0;
    TissueParameters parameters;
  };
  CutJob cut_job_;
  // Written by the job, read after the wait.
  bool job_edited_ = false;
  bool job_reused_ = false;  // the front's published candidates serve on (no refit or search ran)
  ResectionStep job_cut_;
  ResectionStats resection_stats_;  // the core's copy, taken at each collection
  SweptVolume sweep_;
  std::vector<Vec3> wire_loop_;  // the cutting arc in the loop's frame
  std::vector<Vec3> wire_from_, wire_to_;  // the arc in the world at the last and this collision tick
  bool wire_from_valid_ = false;
  bool cut_pedal_ = false;  // this tick's input: tool present and cutting pedal down
  ResectionStep last_cut_;
  /// When the last refit and search ran (written by their thread, read after the wait).
  struct SearchTiming {
    std::uint64_t tick = 0;
    std::int64_t begin_ns = 0, topology_end_ns = 0, refit_end_ns = 0, query_end_ns = 0;
  };
  SearchTiming search_timing_;
  bool search_pending_ = false;  ///< a collision step's candidates await publishing
  std::uint64_t contact_searches_ = 0, contact_searches_reused_ = 0;
  int sheath_part_ = 0;
  int loop_part_ = 0;
  std::size_t tetrahedra_ = 0;
  double verumontanum_z_m_ = 0.0;
  Vec3 loop_front_tool_{0.0};  ///< the loop wire's front, tool frame
  /// Where the tool is, and whether the device has placed it (else it waits withdrawn).
  struct ToolPlacement {
    ToolPoses poses;
    bool present = false;
    bool loop_in_contact = true;  // false while the energised loop cuts (it pushes nothing then)
  };
  ToolPlacement placed_;     // this tick
  DeviceJoints placed_joints_;  // the smoothed joints placed_ was placed by
  DeviceJoints last_search_joints_;  // placed_joints_ at the last collision tick
  bool last_search_present_ = false;
  JointFilter input_filter_;
  ToolPlacement searching_;  // for the search in flight
  ToolPlacement published_;  // for the candidates in use
  ToolReaction reaction_;
  std::uint64_t tick_ = 0;
  std::uint64_t state_hash_ = 0;
  std::uint64_t contact_ticks_ = 0;
  double contact_force_sum_n_ = 0.0;
  double step_peak_force_n_ = 0.0;  // largest_reaction_force_n_of_step()
  bool step_peak_restarts_ = true;  // the coming tick is the first of a collision step's ticks
  ProcedureMetrics metrics_;
  /// Whether the next physics step may share its loops with the helper: not while the core is
  /// overloaded (below).
  bool physics_helper_allowed() const { return physics_helper_ && !(paced_ && std::popcount(waited_ticks_) < 16); }
  /// Whether the collision job is running on its thread now (it then needs the second processor).
  bool collision_job_running() const { return collision_thread_ && !collision_thread_->idle(); }
  // A paced (real-time) core that waited before fewer than half of its last 32 ticks is overloaded:
  // the model is too large for the machine (a catch-up after a stall is a few ticks). It then runs
  // without the helper, which would otherwise hold the second processor too and starve every other
  // thread (the console drew one frame a second at 34560 triangles), until it keeps time again.
  bool paced_ = false;                    // set_paced(): the ticks are paced in real time
  bool waited_ = false;                   // ... and was, before the coming tick
  std::uint32_t waited_ticks_ = ~0u;      // one bit per recent tick: whether the core waited for it
  std::unique_ptr<LoopHelper> physics_helper_;
  std::unique_ptr<JobThread> collision_thread_;  // last: stops before what its job uses goes
};

/// Physics threads worth having on this machine: 2 where it has two or more processors, else 1.
int default_physics_threads();

/// Which of a simulation's own threads a real-time run raised to SCHED_FIFO.
struct RaisedThreads {
  bool collision = false;
  bool physics_helper = false;
  int core_cpu = -1;  ///< the processor the core's thread was kept on (keep_core_apart), or -1
};
/// Real time, once the core's thread holds kCoreFifoPriority: the collision thread under it (it has
/// a whole collision period) and the physics helper level with it (it runs only inside the core's
/// physics step, and the core may wait on a chunk it holds, so nothing the core outranks may
/// preempt it). Call on the core's thread: it also keeps that thread on a processor of its own and
/// the helper off it (keep_core_apart).
RaisedThreads raise_simulation_threads(Simulation& sim);

/// The stages' budgets at a tick rate, microseconds (the tick's time split among its stages).
std::array<double, kStageCount> default_stage_budgets_us(const SimulationConfig& config);

}  // namespace resecto
