// `resecto replay FILE [--verify] [--json]`: re-simulates a recording through the same core from its
// recorded inputs and commands; with --verify, the state hash of every collision step is compared
// and the first tick that differs is named (exit status 1).
#include <algorithm>
#include <cstdio>
#include <memory>
#include <stdexcept>
#include <string>

#include <nlohmann/json.hpp>

#include "console/commands/checked_options.h"
#include "console/commands/command_registry.h"
#include "console/headless/headless_run.h"
#include "recordings/replay.h"

namespace resecto::cli {
namespace {

struct ReplayOptions {
  std::string file;
  bool verify = false;
  bool json = false;
};

void replay(const ReplayOptions& o) {
  Result<rec::Recording> recording = rec::Recording::open(o.file);
  if (!recording) throw std::runtime_error(recording.error());
  Result<std::unique_ptr<rec::Replayer>> replayer = rec::Replayer::create(*recording);
  if (!replayer) throw std::runtime_error(o.file + ": " + replayer.error());
  rec::Replayer& r = **replayer;
  const std::uint64_t ticks = r.run_to(r.end_tick());
  const std::uint64_t recorded_steps = recording->steps().size();
  // The steps the recorder wrote, from its summary: a file recovered from a damaged one holds fewer
  // (rec recover drops the damaged chunks), and those were never compared.
  const std::uint64_t written_steps = std::max(recorded_steps, recording->summary_count("steps").value_or(0));
  const std::string unverified = rec::unverified_hashes(*recording, r);
  // Complete: the whole run the recorder closed, every tick of it replayed. A file never closed
  // (a killed run, or one cut short) replays up to where it stops, but is not the whole run.
  const bool complete = ticks == recording->tick_count() && recording->damaged().empty() && recording->closed();

  nlohmann::ordered_json out = {
      {"file", o.file},
      {"ticks", ticks},
      {"simulated_s", static_cast<double>(ticks) * recording->header().simulation.tick_s()},
      {"state_hash", hex_hash(r.simulation().state_hash())},
      {"verified_hashes", r.verified_hashes()},
      {"recorded_hashes", written_steps},
      {"hashes_in_file", recorded_steps},
      {"mismatches", r.mismatches()},
      {"first_mismatch_tick", r.first_mismatch_tick() ? nlohmann::ordered_json(*r.first_mismatch_tick()) : nlohmann::ordered_json(nullptr)},
      {"complete", complete},
      {"closed", recording->closed()},
      {"unverified", unverified.empty() ? nlohmann::ordered_json(nullptr) : nlohmann::ordered_json(unverified)}};
  if (recording->summary().contains("run")) out["recorded_state_hash"] = recording->summary()["run"].value("state_hash", "");
  if (o.json) {
    std::printf("%s\n", out.dump(2).c_str());
  } else {
    std::printf("replayed %llu ticks (%.2f s) of %s, final state hash %s\n", static_cast<unsigned long long>(ticks),
                out["simulated_s"].get<double>(), o.file.c_str(), out["state_hash"].get<std::string>().c_str());
    if (out.contains("recorded_state_hash")) std::printf("  the run ended with state hash %s\n", out["recorded_state_hash"].get<std::string>().c_str());
    if (ticks < recording->tick_count()) {
      std::printf("  the recording's inputs end or break at tick %llu (%llu ticks recorded, %zu damaged ranges)\n",
                  static_cast<unsigned long long>(ticks), static_cast<unsigned long long>(recording->tick_count()), recording->damaged().size());
    } else if (!recording->damaged().empty()) {
      std::printf("  every recorded tick replayed; the file has %zu damaged ranges (`resecto rec verify` names them)\n", recording->damaged().size());
    }
    if (!recording->closed()) {
      std::printf("  the recording was never closed (no index): it ends where its run stopped writing, not necessarily at the run's end\n");
    }
    // Said with or without --verify: a replay that does not reproduce its recording is news either way
    // (audit 31, F4: two different final hashes and not a word about 105 mismatches).
    std::printf("  %llu of %llu recorded hashes verified, %llu mismatches", static_cast<unsigned long long>(r.verified_hashes()),
                static_cast<unsigned long long>(written_steps), static_cast<unsigned long long>(r.mismatches()));
    if (r.mismatches() > 0) {
      std::printf(", the first at tick %llu: this replay does not reproduce the recording%s", static_cast<unsigned long long>(*r.first_mismatch_tick()),
                  o.verify ? "" : " (`--verify` fails on it)");
    }
    std::printf("\n");
  }
  if (o.verify && r.mismatches() > 0) {
    const std::uint64_t tick = *r.first_mismatch_tick();
    const std::uint64_t period = static_cast<std::uint64_t>(recording->header().simulation.physics_per_collision);
    throw std::runtime_error(o.file + ": replay differs from the recording first at tick " + std::to_string(tick) + " (recorded hash " +
                             hex_hash(r.first_mismatch_recorded()) + ", replayed " + hex_hash(r.first_mismatch_replayed()) +
                             "); the inputs of ticks " + std::to_string(tick >= period ? tick - period + 1 : 0) + ".." + std::to_string(tick) +
                             " or the build differ");
  }
  if (o.verify && r.verified_hashes() == 0) throw std::runtime_error(o.file + ": no collision step's hash could be verified");
  // --verify vouches for the whole recording: hashes it could not compare (damaged, left out by a
  // recovery, past where the inputs end) fail it, though every one compared matched.
  if (o.verify && !unverified.empty()) throw std::runtime_error(unverified);
  // The keyframes take no part in the re-simulation, but --verify vouches for the file: a keyframe
  // that does not decode (the console's timeline and `rec export` would fail on it) fails it.
  if (o.verify) {
    const std::vector<std::string> keyframes = recording->keyframe_problems();
    if (!keyframes.empty()) {
      throw std::runtime_error(keyframes.front() + " (" + std::to_string(keyframes.size()) +
                               " unusable keyframes; every hash compared matched; `resecto rec verify` names them)");
    }
  }
}

void register_replay(CLI::App& app) {
  auto o = std::make_shared<ReplayOptions>();
  CLI::App* cmd = app.add_subcommand("replay", "Re-simulate a recording through the core; --verify compares every collision step's hash");
  cmd->add_option("FILE", o->file, "Recording (from `run --record`)")->required()->check(existing_path());
  cmd->add_flag("--verify", o->verify, "Compare the state hash at every collision step; exit 1 naming the first tick that differs");
  cmd->add_flag("--json", o->json, "Print ticks, verified_hashes, mismatches, state_hash as JSON");
  cmd->callback([o] { replay(*o); });
}

const RegisterCommand kRegister{"replay", &register_replay};

}  // namespace
}  // namespace resecto::cli
