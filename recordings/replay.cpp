// Re-simulation of a recording and the hash comparison at every collision step.
#include "recordings/replay.h"

namespace resecto::rec {

Result<std::unique_ptr<Replayer>> Replayer::create(const Recording& recording) {
  if (recording.header().start_tick != 0) {
    // Re-simulation needs every input from the first tick: a recording started mid-session holds no
    // state to start from (its keyframes are surfaces, not the core's whole state).
    return Error{"replay: " + recording.name() + " starts at tick " + std::to_string(recording.header().start_tick) +
                 " (recorded from mid-session): re-simulation needs the session from tick 0; its keyframes can still be browsed " +
                 "and exported (`rec export`), and `resecto console --record FILE` records a session from its first tick"};
  }
  Result<std::unique_ptr<Simulation>> sim = Simulation::create(recording.header().simulation);
  if (!sim) return Error{"replay: " + sim.error()};
  std::unique_ptr<Replayer> replayer(new Replayer(recording));
  replayer->sim_ = std::move(*sim);
  replayer->end_tick_ = recording.replayable_ticks();
  replayer->tick_commands_.reserve(16);
  return replayer;
}

std::uint64_t Replayer::run_to(std::uint64_t tick) {
  const std::span<const TickRecord> ticks = recording_.ticks();
  const std::span<const StepRecord> steps = recording_.steps();
  const std::span<const ParameterCommand> commands = recording_.commands();
  const std::uint64_t stop = std::min(tick, end_tick_);
  while (sim_->tick() < stop) {
    const std::uint64_t t = sim_->tick();
    const TickRecord& record = ticks[next_tick_record_++];  // replayable ticks are ticks[0..end_tick_)
    tick_commands_.clear();
    while (next_command_ < commands.size() && commands[next_command_].apply_tick <= static_cast<std::int64_t>(t)) {
      if (commands[next_command_].apply_tick == static_cast<std::int64_t>(t)) tick_commands_.push_back(commands[next_command_]);
      ++next_command_;
    }
    sim_->step(record.input, tick_commands_);
    if (!sim_->is_collision_tick(t)) continue;
    while (next_step_ < steps.size() && steps[next_step_].tick < t) ++next_step_;
    if (next_step_ < steps.size() && steps[next_step_].tick == t) {
      const std::uint64_t recorded = steps[next_step_].state_hash;
      if (recorded == sim_->state_hash()) {
        ++verified_;
      } else {
        if (!first_mismatch_) {
          first_mismatch_ = t;
          first_recorded_ = recorded;
          first_replayed_ = sim_->state_hash();
        }
        ++mismatches_;
      }
    }
  }
  return sim_->tick();
}

}  // namespace resecto::rec
