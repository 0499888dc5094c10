// Replay: a fresh Simulation built from the recording's configuration, stepped with the recorded
// inputs and commands; with verification, the state hash at every collision step is compared with
// the recorded one. The core is deterministic, so a faithful recording replays bit-exactly.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>

#include "recordings/recording_reader.h"
#include "rtcore/base/result.h"
#include "rtcore/core/simulation.h"

namespace resecto::rec {

/// Steps a Simulation through a recording; the console's scrubber uses it to re-simulate to a tick.
class Replayer {
 public:
  static Result<std::unique_ptr<Replayer>> create(const Recording& recording);

  /// Runs ticks until `tick` ticks have run since the start (i.e. sim.tick() == tick), or the
  /// recorded inputs end. Returns the tick reached. Cannot go backwards: create a new Replayer.
  std::uint64_t run_to(std::uint64_t tick);
  /// As run_to, checking each collision step's hash against the recording.
  const Simulation& simulation() const { return *sim_; }
  /// Takes in the collision step still in flight (Simulation::settle), as the recorded run did when it
  /// ended: call once the replay has reached the end, before reading the tissue it left.
  void settle() { sim_->settle(); }

  std::uint64_t verified_hashes() const { return verified_; }
  std::uint64_t mismatches() const { return mismatches_; }
  /// The collision tick of the first hash that differed.
  std::optional<std::uint64_t> first_mismatch_tick() const { return first_mismatch_; }
  std::uint64_t first_mismatch_recorded() const { return first_recorded_; }
  std::uint64_t first_mismatch_replayed() const { return first_replayed_; }
  /// The last tick recorded input exists for (exclusive end of what can be replayed).
  std::uint64_t end_tick() const { return end_tick_; }

 private:
  explicit Replayer(const Recording& recording) : recording_(recording), ticks_(recording) {}
  const Recording& recording_;
  TickReader ticks_;
  std::unique_ptr<Simulation> sim_;
  std::size_t next_step_ = 0, next_command_ = 0;
  std::uint64_t end_tick_ = 0;
  std::uint64_t verified_ = 0, mismatches_ = 0;
  std::optional<std::uint64_t> first_mismatch_;
  std::uint64_t first_recorded_ = 0, first_replayed_ = 0;
  std::vector<ParameterCommand> tick_commands_;
};

/// Why a replay run to its end (run_to(end_tick())) cannot vouch for the whole recording though no
/// hash it compared differed: recorded hashes it never compared (in damaged chunks, left out by
/// `rec recover`, or past where the inputs end or break). Empty when it compared every one.
std::string unverified_hashes(const Recording& recording, const Replayer& replayer);

}  // namespace resecto::rec
