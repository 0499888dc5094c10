// Re-simulation of a recording and the hash comparison at every collision step.
#include "recordings/replay.h"

#include <algorithm>

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
  // The header's counts describe the model its settings build; a file that claims others was not
  // written by a recorder of this build (or was edited), and its hashes could not match anyway.
  const SessionHeader& header = recording.header();
  const std::size_t nodes = (*sim)->tissue().node_count(), triangles = (*sim)->prostate().surface.triangle_count();
  if (header.nodes != nodes || header.surface_triangles != triangles) {
    return Error{"replay: " + recording.name() + "'s header says " + std::to_string(header.nodes) + " nodes and " +
                 std::to_string(header.surface_triangles) + " surface triangles, but the model its simulation settings build has " +
                 std::to_string(nodes) + " and " + std::to_string(triangles) + ": the header was edited or written by another build"};
  }
  std::unique_ptr<Replayer> replayer(new Replayer(recording));
  replayer->sim_ = std::move(*sim);
  replayer->end_tick_ = recording.replayable_ticks();
  replayer->tick_commands_.reserve(16);
  return replayer;
}

std::uint64_t Replayer::run_to(std::uint64_t tick) {
  const std::span<const StepEntry> steps = recording_.steps();
  const std::span<const ParameterCommand> commands = recording_.commands();
  const std::uint64_t stop = std::min(tick, end_tick_);
  while (sim_->tick() < stop) {
    const std::uint64_t t = sim_->tick();
    const TickRecord* record = ticks_.next();  // the replayable ticks are the first end_tick_ recorded
    if (record == nullptr) break;
    tick_commands_.clear();
    while (next_command_ < commands.size() && commands[next_command_].apply_tick <= static_cast<std::int64_t>(t)) {
      if (commands[next_command_].apply_tick == static_cast<std::int64_t>(t)) tick_commands_.push_back(commands[next_command_]);
      ++next_command_;
    }
    sim_->step(record->input, tick_commands_);
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

namespace {

/// Why some recorded hashes were never compared, or empty (unverified_hashes adds the file and count).
std::string uncompared_hashes(const Recording& recording, std::uint64_t reached) {
  if (!recording.damaged().empty() || !recording.content_errors().empty()) {
    return "the recording is damaged (" + std::to_string(recording.damaged().size()) + " damaged ranges, " +
           std::to_string(recording.content_errors().size()) + " content problems; `resecto rec verify` names them)";
  }
  const std::uint64_t in_file = recording.steps().size();
  const std::optional<std::uint64_t> written = recording.summary_count("steps");
  const std::uint64_t dropped = recording.recovered_damaged_ranges();
  const std::string by_recovery = dropped > 0 ? " (`resecto rec recover` left out the damaged chunks that held them)" : "";
  if (written && *written > in_file) {
    return std::to_string(*written - in_file) + " of the " + std::to_string(*written) +
           " collision steps' hashes the recorder wrote are not in the file" + by_recovery;
  }
  // Hashes of collision steps the replay never reached: the inputs end or break first (a ticks chunk
  // lost, or the file cut after a steps chunk and before the ticks it covers).
  const auto steps = recording.steps();
  const auto past = static_cast<std::uint64_t>(
      steps.end() - std::lower_bound(steps.begin(), steps.end(), reached, [](const StepEntry& s, std::uint64_t t) { return s.tick < t; }));
  if (past > 0) {
    return std::to_string(past) + " of the " + std::to_string(in_file) + " recorded hashes are of collision steps at or past tick " +
           std::to_string(reached) + ", where the recorded inputs end or break";
  }
  // A recovery of a cut or killed file: the recorder never said how many hashes it wrote, and the
  // damaged ranges the recovery left out (a cut end among them, perhaps) may have held some.
  if (recording.recovered_from_unclosed()) {
    return "`resecto rec recover` made it from a damaged recording that was never closed (" + std::to_string(dropped) +
           " damaged ranges left out): how many hashes those held is unknown";
  }
  return {};
}

}  // namespace

std::string unverified_hashes(const Recording& recording, const Replayer& replayer) {
  const std::string why = uncompared_hashes(recording, replayer.simulation().tick());
  if (why.empty()) return why;
  const std::uint64_t in_file = recording.steps().size();
  const std::uint64_t verified = replayer.verified_hashes();
  const std::uint64_t compared_count = verified + replayer.mismatches();
  // Said as it is: when every hash in the file was compared and matched, what fails is the file's
  // word for the rest ("only 600 could be compared" of 600 read as a failed comparison; audit 25, F5),
  // and a hash that differed was compared ("only 0 of 180 could be compared" beside 180 mismatches;
  // audit 31, F4).
  const std::string compared =
      compared_count == in_file && replayer.mismatches() == 0
          ? "all " + std::to_string(in_file) + " collision steps' hashes in the file matched, which vouches for those alone"
          : std::to_string(compared_count) + " of the " + std::to_string(in_file) + " collision steps' hashes in the file could be compared (" +
                std::to_string(verified) + " matched, " + std::to_string(replayer.mismatches()) + " differed)";
  const std::string remedy = recording.damaged().empty() ? "" : "; `resecto rec recover` keeps what is intact";
  return recording.name() + ": " + why + ": " + compared + remedy;
}

}  // namespace resecto::rec
