// The headless run: device -> core -> snapshots, batch or real time, and its report.
#include "console/headless/headless_run.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <optional>
#include <thread>

#include "console/headless/lockstep_device.h"
#include "console/headless/realtime_advice.h"
#include "console/live/interrupt.h"
#include "console/live/live_device.h"
#include "console/score/rescore.h"
#include "device/link/calibration_adapter.h"
#include "device/calibration/calibration.h"
#include "device/link/tool_input.h"
#include "recordings/recorder.h"
#include "resecto/lp3500_board.h"
#include "rtcore/concurrency/spsc_ring.h"
#include "rtcore/concurrency/triple_buffer.h"
#include "rtcore/core/fixed_step_scheduler.h"
#include "rtcore/core/realtime_duty.h"
#include "rtcore/core/thread_priority.h"
#include "rtcore/mesh/mesh_io.h"
#include "rtcore/base/state_hash.h"

namespace resecto {
namespace {

using nlohmann::ordered_json;

/// Takes the core's snapshots on its own thread, as the console will; optionally slow on purpose.
class SnapshotConsumer {
 public:
  SnapshotConsumer(TripleBuffer<SimulationSnapshot>& snapshots, double delay_ms)
      : snapshots_(snapshots), delay_ms_(delay_ms), thread_([this] { run(); }) {}
  ~SnapshotConsumer() { stop(); }
  void stop() {
    running_.store(false, std::memory_order_release);
    if (thread_.joinable()) thread_.join();
  }
  std::uint64_t received() const { return received_.load(std::memory_order_acquire); }
  std::uint64_t last_tick() const { return last_tick_.load(std::memory_order_acquire); }

 private:
  void run() {
    while (running_.load(std::memory_order_acquire)) {
      if (snapshots_.update()) {
        received_.fetch_add(1, std::memory_order_acq_rel);
        last_tick_.store(snapshots_.read_slot().tick, std::memory_order_release);
        if (delay_ms_ > 0) std::this_thread::sleep_for(std::chrono::duration<double, std::milli>(delay_ms_));
      } else {
        std::this_thread::sleep_for(std::chrono::microseconds(500));
      }
    }
  }

  TripleBuffer<SimulationSnapshot>& snapshots_;
  double delay_ms_;
  std::atomic<bool> running_{true};
  std::atomic<std::uint64_t> received_{0};
  std::atomic<std::uint64_t> last_tick_{0};
  std::thread thread_;
};

ordered_json stage_json(const StageStatistics& s) {
  return {{"median_us", s.median_us}, {"p95_us", s.p95_us}, {"p99_us", s.p99_us}, {"max_us", s.max_us},
          {"budget_us", s.budget_us}, {"samples", s.samples}, {"over_budget", s.over_budget}};
}

ordered_json board_flags_json(const BoardFlagCounts& f) {
  return {{"illegal_transitions", {{"yaw", f.illegal_transitions[0]}, {"pitch", f.illegal_transitions[1]}, {"roll", f.illegal_transitions[2]}}},
          {"sheath_clamped", f.sheath_clamped},
          {"loop_clamped", f.loop_clamped},
          {"stalls", f.stalls},
          {"overruns", f.overruns},
          {"no_adc_sample", f.no_adc_sample}};
}

}  // namespace

ordered_json metrics_json(const ProcedureMetrics& m) {
  return {{"contact_time_s", m.contact_time_s},
          {"cut_pedal_time_s", m.cut_pedal_time_s},
          {"cut_in_contact_time_s", m.cut_in_contact_time_s},
          {"peak_reaction_force_n", m.peak_reaction_force_n},
          {"mean_contact_force_n", m.mean_contact_force_n},
          {"max_tissue_displacement_mm", m.max_tissue_displacement_mm},
          {"max_insertion_mm", m.max_insertion_mm},
          {"distal_margin_mm", m.distal_margin_mm ? ordered_json(*m.distal_margin_mm) : ordered_json(nullptr)},
          {"verumontanum_violations", m.verumontanum_violations},
          {"non_finite_steps", m.non_finite_steps},
          {"contact_overflows", m.contact_overflows},
          {"contact_margin_exceeded_ticks", m.contact_margin_exceeded_ticks},
          {"max_tool_travel_since_search_mm", m.max_tool_travel_since_search_mm},
          {"resected_g", {{"adenoma", m.resected_adenoma_g}, {"capsule", m.resected_capsule_g}, {"total", m.resected_total_g}}},
          {"chips", m.chips},
          {"chips_g", m.chips_g},
          {"cuts", m.cuts},
          {"perforations", m.perforations},
          {"sphincter_zone_violations", m.sphincter_zone_violations},
          {"sphincter_zone_cut_s", m.sphincter_zone_cut_s},
          {"loop_on_idle_s", m.loop_on_idle_s},
          {"initial_tissue_g", m.initial_tissue_g},
          {"remaining_tissue_g", m.remaining_tissue_g},
          {"remaining_adenoma_fraction", m.remaining_adenoma_fraction},
          {"refined_tetrahedra", m.refined_tetrahedra},
          {"topology_refusals", m.topology_refusals}};
}

Result<HeadlessResult> run_headless(const HeadlessOptions& options) {
  SimulationConfig simulation = options.simulation;
  simulation.gimbal = gimbal_geometry_from(options.calibration);
  // The configuration is validated as it is given (Simulation::create copies it), so the run's length
  // is known, and checked, before the model is built. A run shorter than one collision step would
  // report and record nothing a replay or score can use.
  const double seconds = options.seconds > 0.0 ? options.seconds : options.procedure.duration_s();
  const double tick_s = simulation.tick_s();
  const auto ticks = static_cast<std::uint64_t>(std::max<long long>(0, std::llround(seconds / tick_s)));
  if (!simulation.holds_a_collision_step(seconds)) {
    char text[256];
    std::snprintf(text, sizeof text, "the run is %.3g s long (%s); it must last at least one collision step, %.4g s", seconds,
                  options.seconds > 0.0 ? "--seconds" : "the procedure's length", tick_s * simulation.physics_per_collision);
    return Error{text};
  }
  Result<std::unique_ptr<Simulation>> created = [&] {
    const EndAtOnceOnInterrupt nothing_written_yet;
    return Simulation::create(simulation);
  }();
  if (!created) return Error{created.error()};
  // A signal noted before the build: the run never starts, so no file is made or replaced.
  if (const int signal_number = interrupt_signal(); signal_number != 0) {
    throw InterruptedRun(signal_number, "interrupted by " + signal_name(signal_number) + " before the first tick; nothing was run or written");
  }
  Simulation& sim = **created;
  const SimulationConfig& config = sim.config();
  const auto period_ns = static_cast<std::int64_t>(std::llround(tick_s * 1e9));

  // The trace ring: about six stage timings a tick, up to --trace-events of them; without a trace to
  // write, none (audit 10: 120 MB were zeroed for --seconds 3600 and no trace).
  const std::uint64_t trace_capacity = options.trace_path.empty() ? 0 : std::min<std::uint64_t>(ticks * 6 + 64, options.trace_events);
  FrameProfiler profiler(default_stage_budgets_us(config), trace_capacity);
  SchedulerConfig schedule;
  schedule.period_ns = period_ns;
  schedule.realtime = options.realtime;
  schedule.spin_ns = options.spin_us * 1000;
  if (options.realtime) schedule.max_busy_fraction = realtime_busy_limit();
  FixedStepScheduler scheduler(schedule);

  const device::Calibration& calibration = options.calibration;
  SpscRing<DeviceSample> samples(4096);
  ToolInput tool_input;
  std::unique_ptr<LockstepDevice> lockstep;
  std::unique_ptr<LiveDevice> live;
  if (options.realtime) {
    LiveDeviceOptions device_options;
    device_options.procedure = options.procedure;
    device_options.calibration = calibration;
    device_options.seed = options.seed;
    live = std::make_unique<LiveDevice>(device_options);
    live->link().start();
  } else {
    lockstep = std::make_unique<LockstepDevice>(options.procedure, calibration, options.seed);
  }

  std::unique_ptr<rec::Recorder> recorder;
  if (!options.record_path.empty()) {
    rec::SessionHeader description;
    description.procedure = options.procedure.name;
    description.mode = options.realtime ? "realtime" : "batch";
    description.seed = options.seed;
    description.calibration = ordered_json::parse(device::calibration_to_json(calibration));
    Result<std::unique_ptr<rec::Recorder>> started = rec::Recorder::start(options.record_path, std::move(description), sim);
    if (!started) return Error{started.error()};
    recorder = std::move(*started);
  }

  TripleBuffer<SimulationSnapshot> snapshots(sim.make_snapshot());
  SnapshotConsumer consumer(snapshots, options.consumer_delay_ms);

  // The score, live: the same tracker `resecto score` runs over a recording's re-simulation.
  ScoreTracker score(sim);
  score.reserve(ticks / static_cast<std::uint64_t>(config.physics_per_collision) + 2);
  HeadlessResult result;
  result.collision_hashes.reserve(ticks / static_cast<std::uint64_t>(config.physics_per_collision) + 2);
  TimingHistogram input_to_snapshot_us;
  std::int64_t newest_sample_host_ns = 0;   // host receipt of the newest sample latched
  std::int64_t published_sample_host_ns = 0;

  // Real time: the core's thread first, the collision thread next (it has a whole collision period),
  // both before any normal thread of the machine. Batch runs keep normal priority.
  ScopedFifoPriority core_priority(kCoreFifoPriority, options.realtime);
  bool collision_raised = false;
  bool helper_raised = false;
  bool recorder_raised = false;
  int core_cpu = -1;  // the processor the core was kept on (keep_core_apart), -1: wherever the OS put it
  if (core_priority.raised()) {
    const RaisedThreads raised = raise_simulation_threads(sim);
    collision_raised = raised.collision;
    helper_raised = raised.physics_helper;
    core_cpu = raised.core_cpu;
    if (recorder) recorder_raised = raise_to_fifo(recorder->native_handle(), kRecorderFifoPriority);
  }
  const auto wall_start = std::chrono::steady_clock::now();
  if (options.realtime) {
    sim.set_paced();
    scheduler.set_wake_hook([](void* simulation) { static_cast<Simulation*>(simulation)->prepare_for_tick(); }, &sim);
  }
  scheduler.run(0, ticks, [&](std::uint64_t tick) {
    const std::int64_t tick_begin_ns = FrameProfiler::now_ns();
    TickInput input;
    {
      RESECTO_PROFILE_STAGE(&profiler, Stage::kInput, tick);
      if (lockstep) {
        lockstep->advance_to(static_cast<std::uint64_t>(tick) * static_cast<std::uint64_t>(period_ns) / 1000, samples);
      } else {
        relay_link_samples(live->link(), samples, newest_sample_host_ns);
      }
      tool_input.latch(samples, tick_s);
      input = tool_input.tick_input();
    }
    if (recorder) recorder->record_tick(tick, input, {});
    sim.step(input, {}, &profiler);
    if (sim.is_collision_tick(tick)) {
      result.collision_hashes.push_back(sim.state_hash());
      RESECTO_PROFILE_STAGE(&profiler, Stage::kPublish, tick);
      sim.fill_snapshot(snapshots.write_slot());
      snapshots.publish();
      if (recorder) recorder->record_step(sim);
      score.observe(sim);
      if (live && newest_sample_host_ns > published_sample_host_ns) {
        input_to_snapshot_us.add(static_cast<double>(FrameProfiler::now_ns() - newest_sample_host_ns) * 1e-3);
        published_sample_host_ns = newest_sample_host_ns;
      }
    }
    profiler.record(Stage::kTick, tick, tick_begin_ns, FrameProfiler::now_ns());
    return interrupt_signal() == 0;
  });
  result.interrupted_by = interrupt_signal();
  const double wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
  const bool core_raised = core_priority.raised();
  core_priority.restore();
  consumer.stop();
  if (live) live->link().stop();
  // The last collision step's job may still be cutting the other copy: take it in before reading the
  // tissue, the metrics and the score.
  sim.settle();

  result.ticks = sim.tick();
  result.final_hash = sim.state_hash();
  StateHasher chain;
  chain.add(std::span<const std::uint64_t>(result.collision_hashes));

  ordered_json& r = result.report;
  r["ticks"] = result.ticks;
  r["state_hash"] = hex_hash(result.final_hash);
  r["hash_chain"] = hex_hash(chain.value());
  r["collision_steps"] = result.collision_hashes.size();
  // Steps that kept the candidates in use (the tool and tissue had barely moved) ran no refit or search.
  r["contact_searches"] = {{"searched", sim.contact_searches()}, {"reused", sim.contact_searches_reused()}};
  r["mode"] = options.realtime ? "realtime" : "batch";
  r["procedure"] = options.procedure.name;
  if (result.interrupted_by != 0) r["interrupted"] = signal_name(result.interrupted_by);
  r["simulated_s"] = static_cast<double>(result.ticks) * tick_s;
  r["wall_s"] = wall_s;
  r["rates_hz"] = {{"physics", 1.0 / tick_s}, {"collision", config.collision_hz}};
  r["collision_thread"] = config.collision_thread;
  r["physics_threads"] = config.physics_threads;
  if (LoopHelper* helper = sim.physics_helper()) {
    r["physics_helper"] = {{"chunks", helper->chunks_offered()}, {"helped", helper->chunks_helped()}};
  }
  r["scheduling"] = {{"core", core_raised ? "SCHED_FIFO " + std::to_string(kCoreFifoPriority) : std::string("normal")},
                     {"collision", collision_raised ? "SCHED_FIFO " + std::to_string(kCollisionFifoPriority) : std::string("normal")}};
  if (sim.physics_helper()) r["scheduling"]["physics_helper"] = helper_raised ? "SCHED_FIFO " + std::to_string(kCoreFifoPriority) : std::string("normal");
  if (core_cpu >= 0) r["scheduling"]["core_cpu"] = core_cpu;
  if (recorder) r["scheduling"]["recorder"] = recorder_raised ? "SCHED_FIFO " + std::to_string(kRecorderFifoPriority) : std::string("normal");
  r["model"] = {{"surface_triangles", sim.prostate().surface.triangle_count()},
                {"tetrahedra", sim.tetrahedron_count()},
                {"nodes", sim.tissue().node_count()}};
  ordered_json stages = ordered_json::object();
  for (Stage stage : {Stage::kInput, Stage::kKinematics, Stage::kCollisionWait, Stage::kAdopt, Stage::kTopology, Stage::kPhysics, Stage::kRefit, Stage::kQuery,
                      Stage::kResponse, Stage::kPublish, Stage::kTick}) {
    stages[stage_name(stage)] = stage_json(profiler.statistics(stage));
  }
  r["stages"] = stages;
  const DeadlineReport& deadlines = scheduler.report();
  r["deadline_misses"] = deadlines.misses;
  r["deadlines"] = {{"ticks", deadlines.ticks},
                    {"misses", deadlines.misses},
                    {"miss_fraction", deadlines.ticks ? static_cast<double>(deadlines.misses) / static_cast<double>(deadlines.ticks) : 0.0},
                    {"max_late_us", deadlines.max_late_us},
                    {"p99_late_us", deadlines.late_us.quantile(0.99)},
                    {"resynchronizations", deadlines.resynchronizations}};
  if (options.realtime) {
    const RealtimeFigures figures = realtime_figures(r);
    if (std::string advice = realtime_advice(figures); !advice.empty()) {
      r["deadlines"]["advice"] = std::move(advice);
      if (const std::int64_t substeps = advised_substeps(figures); substeps > 0) r["deadlines"]["advised_substeps"] = substeps;
    }
  }
  if (lockstep) {
    const LockstepCounters& c = lockstep->counters();
    r["device"] = {{"transport", "emulator (lockstep)"}, {"reports", c.reports}, {"accepted", c.accepted}, {"lost", c.lost},
                   {"duplicates", c.duplicates}, {"rejected", c.rejected},
                   {"rate_hz", r["simulated_s"].get<double>() > 0 ? static_cast<double>(c.accepted) / r["simulated_s"].get<double>() : 0.0},
                   {"board_flags", board_flags_json(c.board_flags)}};
  } else {
    const LinkCounters c = live->link().counters();
    r["device"] = {{"transport", "emulator (link thread)"}, {"reports", c.reports}, {"accepted", c.accepted}, {"lost", c.lost},
                   {"duplicates", c.duplicates}, {"rejected", c.rejected}, {"rate_hz", c.rate_hz},
                   {"latency_us", {{"median", c.latency_median_us}, {"p99", c.latency_p99_us}}},
                   {"board_flags", board_flags_json(c.board_flags)}};
    r["input_to_snapshot_us"] = {{"median", input_to_snapshot_us.quantile(0.5)}, {"p99", input_to_snapshot_us.quantile(0.99)},
                                 {"max", input_to_snapshot_us.max()}};
  }
  r["snapshots"] = {{"published", result.collision_hashes.size()}, {"received", consumer.received()}};
  r["metrics"] = metrics_json(sim.metrics());
  r["score"] = score_metrics_json(score.finish(sim).metrics);
  if (recorder) {
    ordered_json run = {{"ticks", result.ticks}, {"state_hash", hex_hash(result.final_hash)}};
    // So that a score of the file says the procedure was cut short, not finished (audit 31, F3).
    if (result.interrupted_by != 0) run["interrupted"] = signal_name(result.interrupted_by);
    Result<rec::RecorderCounters> recorded = recorder->finish(run);
    if (!recorded) return Error{"recording " + options.record_path + ": " + recorded.error()};
    r["recording"] = {{"path", options.record_path},
                      {"bytes", recorded->bytes},
                      {"ticks", recorded->ticks},
                      {"steps", recorded->steps},
                      {"keyframes", recorded->keyframes},
                      {"lost", {{"ticks", recorded->ticks_lost}, {"steps", recorded->steps_lost}, {"commands", recorded->commands_lost},
                                {"keyframes", recorded->keyframes_lost}}},
                      {"keyframe_encode_ms", {{"mean", recorded->keyframe_encode_ms_mean}, {"max", recorded->keyframe_encode_ms_max}}}};
  }
  if (profiler.trace_dropped() > 0) {
    r["trace_dropped_events"] = profiler.trace_dropped();
    r["trace_kept_events"] = profiler.trace_capacity();
    r["trace_first_s"] = static_cast<double>(profiler.trace_first_tick()) * tick_s;
  }

  if (!options.export_surface_path.empty()) {
    // At rest: the resected shape itself, not its deformation at the last tick.
    const TriangleMesh surface = sim.tissue().live_surface(true);
    if (Status written = write_surface_mesh(options.export_surface_path, surface); !written) return Error{written.error()};
    result.report["surface"] = {{"path", options.export_surface_path}, {"triangles", surface.triangle_count()}, {"vertices", surface.vertex_count()}};
  }
  if (!options.trace_path.empty()) {
    if (Status written = profiler.write_chrome_trace(options.trace_path); !written) return Error{written.error()};
  }
  return result;
}

std::string summarize_report(const ordered_json& r) {
  char text[2048];
  const auto& m = r.at("metrics");
  const auto& physics = r.at("stages").at("physics");
  const auto& refit = r.at("stages").at("refit");
  const auto& query = r.at("stages").at("query");
  const auto& wait = r.at("stages").at("collision_wait");
  const auto& tick = r.at("stages").at("tick");
  std::snprintf(text, sizeof text,
                "%s run of '%s': %llu ticks (%.2f s simulated in %.2f s), final state hash %s\n"
                "  model      %llu surface triangles, %llu tetrahedra\n"
                "  physics    median %.0f us, p99 %.0f us (budget %.0f us)\n"
                "  refit      median %.0f us, p99 %.0f us (budget %.0f us)\n"
                "  query      median %.0f us, p99 %.0f us (budget %.0f us), %s; core waited for it: p99 %.0f us\n"
                "  tick       median %.0f us, p99 %.0f us, max %.0f us; deadline misses %llu\n"
                "  device     %llu reports, %llu lost, %.0f Hz\n"
                "  procedure  contact %.2f s, peak force %.2f N, cut pedal %.2f s (%.2f s in contact), tissue moved up to %.2f mm\n",
                r.at("mode").get<std::string>().c_str(), r.at("procedure").get<std::string>().c_str(),
                static_cast<unsigned long long>(r.at("ticks").get<std::uint64_t>()), r.at("simulated_s").get<double>(),
                r.at("wall_s").get<double>(), r.at("state_hash").get<std::string>().c_str(),
                static_cast<unsigned long long>(r.at("model").at("surface_triangles").get<std::uint64_t>()),
                static_cast<unsigned long long>(r.at("model").at("tetrahedra").get<std::uint64_t>()), physics.at("median_us").get<double>(),
                physics.at("p99_us").get<double>(), physics.at("budget_us").get<double>(), refit.at("median_us").get<double>(),
                refit.at("p99_us").get<double>(), refit.at("budget_us").get<double>(), query.at("median_us").get<double>(),
                query.at("p99_us").get<double>(), query.at("budget_us").get<double>(),
                r.at("collision_thread").get<bool>() ? "on the collision thread" : "on the core's thread",
                wait.at("p99_us").get<double>(), tick.at("median_us").get<double>(),
                tick.at("p99_us").get<double>(), tick.at("max_us").get<double>(),
                static_cast<unsigned long long>(r.at("deadline_misses").get<std::uint64_t>()),
                static_cast<unsigned long long>(r.at("device").at("reports").get<std::uint64_t>()),
                static_cast<unsigned long long>(r.at("device").at("lost").get<std::uint64_t>()), r.at("device").at("rate_hz").get<double>(),
                m.at("contact_time_s").get<double>(), m.at("peak_reaction_force_n").get<double>(), m.at("cut_pedal_time_s").get<double>(),
                m.at("cut_in_contact_time_s").get<double>(), m.at("max_tissue_displacement_mm").get<double>());
  std::string summary = text;
  // Only the JSON said so (audit 32, F11): a procedure that moves the tool further between two contact
  // searches than their margin covers may pass through tissue without a contact being found.
  if (const auto outran = m.at("contact_margin_exceeded_ticks").get<std::uint64_t>(); outran > 0) {
    // In real time, reports that come late or are lost make the tool jump as a fast hand would; the
    // procedure is then not the only suspect (audit 8, G10: a --spin-us that starved the link thread
    // lost 267 reports, and the warning blamed the procedure, which in batch stays within the margin).
    const std::string cause =
        r.at("mode") == "realtime"
            ? "the procedure moves faster than a hand can, or the device's reports came late or were lost (" +
                  std::to_string(r.at("device").at("lost").get<std::uint64_t>()) +
                  " lost: a core that starves the link thread, a long --spin-us or a loaded machine; the same procedure in batch tells which)"
            : std::string("the procedure moves faster than a hand can");
    std::snprintf(text, sizeof text,
                  "  warning    on %llu ticks the tool had moved past the contact search's margin since the last search (up to %.2f mm): "
                  "contacts there may have been missed; %s\n",
                  static_cast<unsigned long long>(outran), m.at("max_tool_travel_since_search_mm").get<double>(), cause.c_str());
    summary += text;
  }
  // A flagged encoder lost counts: its angle is off from there on, though every report passed its CRC.
  if (r.at("device").contains("board_flags")) {
    for (const auto& [encoder, reports] : r.at("device").at("board_flags").at("illegal_transitions").items()) {
      if (reports.get<std::uint64_t>() == 0) continue;
      std::snprintf(text, sizeof text,
                    "  warning    the %s encoder flagged an illegal transition in %llu reports: the joint turned faster than the board "
                    "decodes (%u counts/s, %.0f deg/s at %d counts a turn), so its angle was wrong from the first one on\n",
                    encoder.c_str(), static_cast<unsigned long long>(reports.get<std::uint64_t>()), LP3500_MAX_COUNT_RATE_HZ,
                    LP3500_MAX_COUNT_RATE_HZ * 360.0 / firmware::SensorModel{}.counts_per_revolution,
                    firmware::SensorModel{}.counts_per_revolution);
      summary += text;
    }
    if (const auto overruns = r.at("device").at("board_flags").at("overruns").get<std::uint64_t>(); overruns > 0) {
      std::snprintf(text, sizeof text, "  warning    the board's capture rings overflowed in %llu reports: readings were lost on the board\n",
                    static_cast<unsigned long long>(overruns));
      summary += text;
    }
  }
  // A long run's trace holds only its end: said here, not only in the JSON (audit 10, finding 3).
  if (r.contains("trace_dropped_events")) {
    std::snprintf(text, sizeof text,
                  "  warning    the trace holds the run from %.1f s to its end at %.1f s: it keeps the last %llu stage timings "
                  "(%llu earlier ones dropped)\n",
                  r.at("trace_first_s").get<double>(), r.at("simulated_s").get<double>(), static_cast<unsigned long long>(r.at("trace_kept_events").get<std::uint64_t>()),
                  static_cast<unsigned long long>(r.at("trace_dropped_events").get<std::uint64_t>()));
    summary += text;
  }
  if (r.contains("recording")) {
    const auto& recording = r.at("recording");
    const auto& lost = recording.at("lost");
    std::snprintf(text, sizeof text, "  recording  %s: %.2f MB, %llu ticks, %llu keyframes (encode mean %.2f ms, max %.2f ms), lost %llu\n",
                  recording.at("path").get<std::string>().c_str(), static_cast<double>(recording.at("bytes").get<std::uint64_t>()) / 1e6,
                  static_cast<unsigned long long>(recording.at("ticks").get<std::uint64_t>()),
                  static_cast<unsigned long long>(recording.at("keyframes").get<std::uint64_t>()), recording.at("keyframe_encode_ms").at("mean").get<double>(),
                  recording.at("keyframe_encode_ms").at("max").get<double>(),
                  static_cast<unsigned long long>(lost.at("ticks").get<std::uint64_t>() + lost.at("steps").get<std::uint64_t>() +
                                                  lost.at("commands").get<std::uint64_t>() + lost.at("keyframes").get<std::uint64_t>()));
    summary += text;
  }
  const auto& topology = r.at("stages").at("topology");
  std::snprintf(text, sizeof text,
                "  resection  %.2f g resected (adenoma %.2f, capsule %.2f), %.1f%% of the adenoma remains; cuts %llu, chips %llu "
                "(%.2f g), refined tetrahedra %llu; perforations %llu, sphincter-zone violations %llu; topology update p99 %.0f us\n",
                m.at("resected_g").at("total").get<double>(), m.at("resected_g").at("adenoma").get<double>(),
                m.at("resected_g").at("capsule").get<double>(), 100.0 * m.at("remaining_adenoma_fraction").get<double>(),
                static_cast<unsigned long long>(m.at("cuts").get<std::uint64_t>()), static_cast<unsigned long long>(m.at("chips").get<std::uint64_t>()),
                m.at("chips_g").get<double>(), static_cast<unsigned long long>(m.at("refined_tetrahedra").get<std::uint64_t>()),
                static_cast<unsigned long long>(m.at("perforations").get<std::uint64_t>()),
                static_cast<unsigned long long>(m.at("sphincter_zone_violations").get<std::uint64_t>()), topology.at("p99_us").get<double>());
  summary += text;
  if (r.at("mode") == "realtime") {
    const auto& d = r.at("deadlines");
    std::snprintf(text, sizeof text,
                  "  deadlines  %llu of %llu ticks missed (%.3f%%), worst %.0f us late, %llu re-anchorings; "
                  "threads: core %s, collision %s\n",
                  static_cast<unsigned long long>(d.at("misses").get<std::uint64_t>()),
                  static_cast<unsigned long long>(d.at("ticks").get<std::uint64_t>()), 100.0 * d.at("miss_fraction").get<double>(),
                  d.at("max_late_us").get<double>(), static_cast<unsigned long long>(d.at("resynchronizations").get<std::uint64_t>()),
                  r.at("scheduling").at("core").get<std::string>().c_str(), r.at("scheduling").at("collision").get<std::string>().c_str());
    summary += text;
    if (d.contains("advice")) summary += "  advice     " + d.at("advice").get<std::string>() + "\n";
  }
  return summary;
}

}  // namespace resecto
