// The core's thread for the console: the headless real-time tick, plus pause, steps, slow motion and
// stamped parameter changes taken from the console's ring at tick boundaries.
#include "console/live/core_session.h"

#include <algorithm>
#include <optional>

#include "console/headless/headless_run.h"
#include "console/headless/lockstep_device.h"
#include "console/live/interrupt.h"
#include "device/calibration/calibration.h"
#include "device/link/calibration_adapter.h"
#include "recordings/recorder.h"
#include "rtcore/core/realtime_duty.h"
#include "rtcore/core/thread_priority.h"

namespace resecto {
namespace {

constexpr std::size_t kPendingCapacity = 256;  // the control ring's capacity: every queued change fits
/// A batch step while paused uses at most this share of each tick's period, so the console and the
/// device link keep their time; the rest of the batch continues at the next tick.
constexpr double kBatchShareOfPeriod = 0.6;

SchedulerConfig schedule_for(const CoreSessionOptions& options) {
  SchedulerConfig schedule;
  schedule.period_ns = static_cast<std::int64_t>(std::llround(options.simulation.tick_s() * 1e9));
  schedule.realtime = true;
  schedule.spin_ns = options.spin_us * 1000;
  schedule.max_busy_fraction = realtime_busy_limit();
  return schedule;
}

/// Copies `text` into a fixed buffer, cut to fit.
template <std::size_t N>
void copy_text(std::array<char, N>& out, const std::string& text) {
  const std::size_t n = std::min(text.size(), N - 1);
  std::copy_n(text.data(), n, out.data());
  out[n] = '\0';
}

}  // namespace

Result<std::unique_ptr<CoreSession>> CoreSession::create(const CoreSessionOptions& options) {
  if (options.lockstep && options.device.source != DeviceSource::kEmulatorScript) {
    return Error{"lockstep runs need the scripted emulator (--device emulator)"};
  }
  SimulationConfig simulation = options.simulation;
  simulation.gimbal = gimbal_geometry_from(options.device.calibration);
  Result<std::unique_ptr<Simulation>> created = Simulation::create(simulation);
  if (!created) return Error{created.error()};
  CoreSessionOptions adjusted = options;
  adjusted.simulation = simulation;
  return std::unique_ptr<CoreSession>(new CoreSession(adjusted, std::move(*created)));
}

CoreSession::CoreSession(const CoreSessionOptions& options, std::unique_ptr<Simulation> sim)
    : options_(options),
      sim_(std::move(sim)),
      profiler_(default_stage_budgets_us(sim_->config()), options.trace_capacity),
      scheduler_(schedule_for(options)),
      frames_(LiveFrame{sim_->make_snapshot(), CoreStatus{}}) {
  if (options.lockstep) {
    lockstep_ = std::make_unique<LockstepDevice>(options.device.procedure, options.device.calibration, options.device.seed);
  } else {
    live_ = std::make_unique<LiveDevice>(options.device);
  }
  pending_.reserve(kPendingCapacity);
  pending_ids_.reserve(kPendingCapacity);
  due_.reserve(kPendingCapacity);
  hashes_.reserve(options.hash_capacity);
  status_.parameters = sim_->tissue().parameters();
  status_.applied_tick.fill(-1);
  for (int s = 0; s < kStageCount; ++s) status_.budget_us[static_cast<std::size_t>(s)] = profiler_.budget_us(static_cast<Stage>(s));
  next_tick_.store(sim_->tick(), std::memory_order_release);
  publish();
}

CoreSession::~CoreSession() { stop(); }

std::string CoreSession::device_description() const {
  return live_ ? live_->description() : "emulator (lockstep, procedure " + options_.device.procedure.name + ")";
}

void CoreSession::start() {
  if (thread_.joinable()) return;
  if (live_) live_->link().start();
  stop_requested_.store(false, std::memory_order_release);
  thread_ = std::thread([this] { run_core(); });
}

void CoreSession::stop() {
  stop_requested_.store(true, std::memory_order_release);
  if (thread_.joinable()) thread_.join();
  if (live_) live_->link().stop();
}

void CoreSession::prepare_for_tick() {
  // Only for a tick that steps: called in for a paused or slowed tick, the helper would spin on call
  // through it (until it went home by itself) and again at every such tick, a processor held for
  // nothing while the console waits. A batch step while paused runs without it.
  if (!status_.paused && speed_credit_ + status_.speed >= 1.0) sim_->prepare_for_tick();
}

void CoreSession::run_core() {
  // The core first, the collision thread next, as in the headless real-time run; the console's own
  // thread stays at normal priority, so a slow frame can never hold a tick back.
  ScopedFifoPriority priority(kCoreFifoPriority, options_.realtime_priority);
  if (priority.raised()) core_cpu_.store(raise_simulation_threads(*sim_).core_cpu, std::memory_order_release);
  priority_held_.store(priority.raised(), std::memory_order_release);
  const double period_ns = static_cast<double>(schedule_for(options_).period_ns);
  sim_->set_paced();
  scheduler_.set_wake_hook([](void* session) { static_cast<CoreSession*>(session)->prepare_for_tick(); }, this);
  scheduler_.run(0, UINT64_MAX / 2, [&](std::uint64_t) {
    if (stop_requested_.load(std::memory_order_acquire)) return false;
    const std::int64_t begin_ns = FrameProfiler::now_ns();
    const bool was_paused = status_.paused;
    take_controls();
    if (!status_.paused) {
      // Slow motion runs a tick only on some periods; real speed runs one every period.
      speed_credit_ = std::min(speed_credit_ + status_.speed, 1.0);
      if (speed_credit_ >= 1.0) {
        speed_credit_ -= 1.0;
        step_once();
      }
    } else if (status_.pending_steps > 0) {
      do {
        step_once();
        --status_.pending_steps;
      } while (status_.pending_steps > 0 &&
               static_cast<double>(FrameProfiler::now_ns() - begin_ns) < kBatchShareOfPeriod * period_ns);
      if (status_.pending_steps == 0) publish();  // the console sees where a step ended
    } else if (live_) {
      // Paused: keep the link's ring drained (only the newest reading matters when the core resumes).
      DeviceSample sample;
      while (live_->link().samples().try_pop(sample)) {
        if (sample.event == LinkEvent::kSample) status_.newest_sample_host_ns = std::max(status_.newest_sample_host_ns, sample.host_time_ns);
        if (sample.event != LinkEvent::kSample || samples_.size_approx() < samples_.capacity() / 2) samples_.try_push(sample);
      }
    }
    if (status_.paused != was_paused) publish();
    return true;
  });
  if (recorder_) finish_recording();
  priority.restore();
}

void CoreSession::start_recording(const std::string& path) {
  if (recorder_) return;
  rec::SessionHeader description;
  // What drove the tool: the procedure only when the board followed it; a person's hands otherwise, or
  // a cohort's CSV could not tell a trainee's session from the scripted demo (audit 8, G14).
  switch (options_.device.source) {
    case DeviceSource::kEmulatorScript: description.procedure = options_.device.procedure.name; break;
    case DeviceSource::kEmulatorManual: description.procedure = "hand-driven (keyboard, mouse or gamepad)"; break;
    case DeviceSource::kHid: description.procedure = "hand-driven (LP3500 over USB HID)"; break;
  }
  description.mode = "console";
  description.seed = options_.device.seed;
  description.calibration = nlohmann::ordered_json::parse(device::calibration_to_json(options_.device.calibration));
  Result<std::unique_ptr<rec::Recorder>> started = rec::Recorder::start(path, std::move(description), *sim_);
  if (!started) {
    copy_text(status_.recording_message, "recording " + path + ": " + started.error());
    if (first_recording_error_.empty()) first_recording_error_ = "recording " + path + ": " + started.error();
  } else {
    recorder_ = std::move(*started);
    status_.recording = true;
    status_.recording_start_tick = sim_->tick();
    status_.recording_lost = 0;
    copy_text(status_.recording_path, path);
    copy_text(status_.recording_partial_path, recorder_->partial_path());
    status_.recording_message[0] = '\0';
  }
  publish();
}

void CoreSession::finish_recording() {
  if (!recorder_) return;
  nlohmann::ordered_json run = {{"ticks", sim_->tick()}, {"state_hash", hex_hash(sim_->state_hash())}};
  // A session closed by Ctrl-C is a procedure cut short, as a headless run's (audit 8, G18).
  if (const int signal_number = interrupt_signal(); signal_number != 0) run["interrupted"] = signal_name(signal_number);
  const std::string path(status_.recording_path.data());
  Result<rec::RecorderCounters> finished = recorder_->finish(run);
  recorder_.reset();
  status_.recording = false;
  ++status_.recordings_finished;
  if (!finished) {
    copy_text(status_.recording_message, "recording: " + finished.error());
    if (first_recording_error_.empty()) first_recording_error_ = "recording " + path + ": " + finished.error();
  } else {
    status_.recorded_bytes = finished->bytes;
    status_.recorded_ticks = finished->ticks;
    status_.recorded_keyframes = finished->keyframes;
    status_.recording_lost = finished->ticks_lost + finished->steps_lost + finished->commands_lost + finished->keyframes_lost;
    if (!finished->write_error.empty()) {
      copy_text(status_.recording_message, "recording: " + finished->write_error);
      if (first_recording_error_.empty()) first_recording_error_ = "recording " + path + ": " + finished->write_error;
    }
  }
  publish();
}

void CoreSession::take_controls() {
  CoreControl control;
  while (controls_.try_pop(control)) {
    switch (control.kind) {
      case CoreControlKind::kParameter:
        if (pending_.size() < kPendingCapacity) {
          pending_.push_back(control.parameter);
          pending_ids_.push_back(control.id);
        }
        break;
      case CoreControlKind::kPause: status_.paused = true; break;
      case CoreControlKind::kResume:
        status_.paused = false;
        status_.pending_steps = 0;
        break;
      case CoreControlKind::kStep:
        if (status_.paused) status_.pending_steps += control.steps;
        break;
      case CoreControlKind::kSpeed: status_.speed = std::clamp(control.speed, kSlowestCoreSpeed, 1.0); break;
      case CoreControlKind::kRecordStart: start_recording(control.path); break;
      case CoreControlKind::kRecordStop: finish_recording(); break;
    }
  }
}

void CoreSession::step_once() {
  const std::uint64_t tick = sim_->tick();
  const std::int64_t tick_begin_ns = FrameProfiler::now_ns();
  const double tick_s = sim_->config().tick_s();
  TickInput input;
  {
    RESECTO_PROFILE_STAGE(&profiler_, Stage::kInput, tick);
    if (lockstep_) {
      const auto period_ns = static_cast<std::uint64_t>(std::llround(tick_s * 1e9));
      lockstep_->advance_to(tick * period_ns / 1000, samples_);
    } else {
      relay_link_samples(live_->link(), samples_, status_.newest_sample_host_ns);
    }
    tool_input_.latch(samples_, tick_s);
    input = tool_input_.tick_input();
    // Commands due now, in the order the console queued them (the same order on replay).
    due_.clear();
    std::size_t kept = 0;
    for (std::size_t i = 0; i < pending_.size(); ++i) {
      ParameterCommand command = pending_[i];
      // A command stamped for a tick already run (the console read the tick just before the core
      // advanced) takes effect now, the core's next tick; the status says which tick that was.
      if (command.apply_tick <= static_cast<std::int64_t>(tick)) {
        command.apply_tick = static_cast<std::int64_t>(tick);
        due_.push_back(command);
        const auto p = static_cast<std::size_t>(command.id);
        status_.applied_tick[p] = static_cast<std::int64_t>(tick);
        status_.applied_id[p] = pending_ids_[i];
      } else {
        pending_[kept] = pending_[i];
        pending_ids_[kept] = pending_ids_[i];
        ++kept;
      }
    }
    pending_.resize(kept);
    pending_ids_.resize(kept);
  }
  if (recorder_) recorder_->record_tick(tick, input, due_);
  sim_->step(input, due_, &profiler_);
  status_.joints = input.joints;
  status_.pedals = tool_input_.pedals();
  status_.input_state = tool_input_.state();
  if (!due_.empty()) status_.parameters = sim_->tissue().parameters();
  profiler_.record(Stage::kTick, tick, tick_begin_ns, FrameProfiler::now_ns());
  for (int s = 0; s < kStageCount; ++s) {
    auto& peak = since_publish_max_us_[static_cast<std::size_t>(s)];
    peak = std::max(peak, static_cast<float>(profiler_.last_us(static_cast<Stage>(s))));
  }
  next_tick_.store(sim_->tick(), std::memory_order_release);
  if (sim_->is_collision_tick(tick)) {
    if (hashes_.size() < hashes_.capacity()) hashes_.emplace_back(tick, sim_->state_hash());
    if (recorder_) {
      recorder_->record_step(*sim_);
      status_.recording_lost = recorder_->lost();
    }
    // One history entry per collision step: the worst tick of each stage since the last entry.
    for (std::size_t s = 0; s < static_cast<std::size_t>(kStageCount); ++s) {
      status_.history_us[s][status_.history_next] = since_publish_max_us_[s];
      since_publish_max_us_[s] = 0.0f;
    }
    status_.history_next = static_cast<std::uint32_t>((status_.history_next + 1) % kStageHistoryLength);
    status_.history_count = std::min<std::uint32_t>(status_.history_count + 1, kStageHistoryLength);
    RESECTO_PROFILE_STAGE(&profiler_, Stage::kPublish, tick);
    publish();
  }
}

void CoreSession::publish() {
  LiveFrame& frame = frames_.write_slot();
  sim_->fill_snapshot(frame.snapshot);
  status_.next_tick = sim_->tick();
  const DeadlineReport& deadlines = scheduler_.report();
  status_.deadline_ticks = deadlines.ticks;
  status_.deadline_misses = deadlines.misses;
  status_.resynchronizations = deadlines.resynchronizations;
  status_.max_late_us = deadlines.max_late_us;
  // The percentiles scan each stage's histogram (thousands of bins): refreshed twice a second only.
  if (publishes_++ % 30 == 0) {
    for (int s = 0; s < kStageCount; ++s) {
    const StageStatistics st = profiler_.statistics(static_cast<Stage>(s));
    status_.median_us[static_cast<std::size_t>(s)] = st.median_us;
    status_.p99_us[static_cast<std::size_t>(s)] = st.p99_us;
    status_.over_budget[static_cast<std::size_t>(s)] = st.over_budget;
    }
  }
  if (lockstep_) {
    status_.lockstep_reports = lockstep_->counters().reports;
    status_.lockstep_lost = lockstep_->counters().lost;
  }
  frame.status = status_;
  frames_.publish();
}

}  // namespace resecto
