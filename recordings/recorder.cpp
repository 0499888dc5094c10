// The recorder thread and the core's lock-free hand-off to it.
#include "recordings/recorder.h"

#include <algorithm>
#include <chrono>

namespace resecto::rec {

Recorder::Recorder(const RecorderSettings& settings, const Simulation& sim)
    : settings_(settings),
      physics_per_collision_(sim.config().physics_per_collision),
      ticks_(settings.tick_ring),
      steps_(settings.step_ring),
      commands_(settings.command_ring),
      free_slots_(static_cast<std::size_t>(settings.keyframe_slots)),
      filled_slots_(static_cast<std::size_t>(settings.keyframe_slots)) {
  keyframe_pool_.reserve(static_cast<std::size_t>(settings.keyframe_slots));
  for (int i = 0; i < settings.keyframe_slots; ++i) {
    keyframe_pool_.push_back(sim.make_snapshot());
    free_slots_.try_push(i);
  }
  pending_ticks_.reserve(settings.ticks_per_chunk);
  pending_steps_.reserve(settings.steps_per_chunk);
}

Result<std::unique_ptr<Recorder>> Recorder::start(const std::filesystem::path& path, SessionHeader description, const Simulation& sim,
                                                  const RecorderSettings& settings) {
  if (settings.keyframe_every_steps < 1 || settings.keyframe_slots < 1) return Error{"recorder: bad settings"};
  std::unique_ptr<Recorder> recorder(new Recorder(settings, sim));
  SessionHeader& h = recorder->header_;
  h = std::move(description);
  h.format_version = kFormatVersion;
  h.build = build_identity();
  h.simulation = sim.config();
  h.start_tick = static_cast<std::int64_t>(sim.tick());
  h.keyframe_every_steps = settings.keyframe_every_steps;
  h.surface_triangles = static_cast<std::uint32_t>(sim.prostate().surface.triangle_count());
  h.nodes = static_cast<std::uint32_t>(sim.tissue().node_count());
  h.metric_words = kMetricWords;
  // One grid for the whole recording: the gland's bounds at the start, grown by a margin that holds
  // any displacement the tissue survives (it is anchored to the pelvis: a few mm at most).
  Vec3 lo(1e30), hi(-1e30);
  for (const Vec3& p : sim.prostate().surface.positions) {
    lo = glm::min(lo, p);
    hi = glm::max(hi, p);
  }
  h.grid = grid_for_bounds(lo, hi, settings.quantisation_bits, 0.010);

  if (Status opened = recorder->writer_.open(path); !opened) return Error{opened.error()};
  const std::string text = header_to_json(h).dump();
  recorder->writer_.add_chunk(ChunkType::kHeader, std::span(reinterpret_cast<const std::uint8_t*>(text.data()), text.size()));
  if (Status flushed = recorder->writer_.flush(); !flushed) return Error{flushed.error()};
  Recorder* self = recorder.get();
  recorder->thread_ = std::thread([self] { self->run(); });
  return recorder;
}

Recorder::~Recorder() {
  running_.store(false, std::memory_order_release);
  if (thread_.joinable()) thread_.join();
}

void Recorder::record_tick(std::uint64_t tick, const TickInput& input, std::span<const ParameterCommand> commands) {
  // Commands first: the recorder thread then always holds a tick's commands before the tick, and
  // writes them out first (write_ticks), so no prefix of the file has a tick without its commands.
  for (const ParameterCommand& c : commands) {
    if (!commands_.try_push(c)) commands_lost_.fetch_add(1, std::memory_order_relaxed);
  }
  if (!ticks_.try_push(TickRecord{tick, input})) ticks_lost_.fetch_add(1, std::memory_order_relaxed);
}

void Recorder::record_step(const Simulation& sim) {
  const std::uint64_t tick = sim.tick() - 1;  // step() has advanced past the collision tick
  StepRecord step;
  step.tick = tick;
  step.state_hash = sim.state_hash();
  step.tool = sim.tool_poses();
  step.metrics = sim.metrics();
  if (!steps_.try_push(std::move(step))) steps_lost_.fetch_add(1, std::memory_order_relaxed);
  const std::uint64_t step_index = tick / static_cast<std::uint64_t>(physics_per_collision_);
  if (step_index % static_cast<std::uint64_t>(settings_.keyframe_every_steps) != 0) return;
  int slot = -1;
  if (!free_slots_.try_pop(slot)) {
    keyframes_lost_.fetch_add(1, std::memory_order_relaxed);
    return;
  }
  sim.fill_snapshot(keyframe_pool_[static_cast<std::size_t>(slot)]);  // copies into preallocated arrays
  filled_slots_.try_push(slot);  // never full: it holds at most every slot
}

std::uint64_t Recorder::lost() const {
  return ticks_lost_.load(std::memory_order_relaxed) + steps_lost_.load(std::memory_order_relaxed) +
         commands_lost_.load(std::memory_order_relaxed) + keyframes_lost_.load(std::memory_order_relaxed);
}

void Recorder::note_error(const Status& status) {
  if (!status && counters_.write_error.empty()) counters_.write_error = status.error();
}

void Recorder::take_commands() {
  ParameterCommand command;
  while (commands_.try_pop(command)) pending_commands_.push_back(command);
}

void Recorder::write_ticks() {
  if (pending_ticks_.empty()) return;
  // The core pushes a tick's commands before the tick: taken now, after the ticks, they include
  // every command of every tick about to be written, and go out first.
  take_commands();
  write_commands();
  // A lost tick breaks the run of consecutive ticks a block holds: split there.
  std::size_t begin = 0;
  for (std::size_t i = 1; i <= pending_ticks_.size(); ++i) {
    if (i == pending_ticks_.size() || pending_ticks_[i].tick != pending_ticks_[i - 1].tick + 1) {
      const std::span<const TickRecord> run(pending_ticks_.data() + begin, i - begin);
      encode_tick_block(run, payload_);
      writer_.add_chunk(ChunkType::kTicks, payload_, run.front().tick);
      ++counters_.chunks;
      begin = i;
    }
  }
  counters_.ticks += pending_ticks_.size();
  last_tick_written_ = pending_ticks_.back().tick;
  pending_ticks_.clear();
}

void Recorder::write_steps(std::size_t count) {
  count = std::min(count, pending_steps_.size());
  if (count == 0) return;
  const std::span<const StepRecord> block(pending_steps_.data(), count);
  encode_step_block(block, payload_);
  writer_.add_chunk(ChunkType::kSteps, payload_, block.front().tick);
  ++counters_.chunks;
  counters_.steps += count;
  pending_steps_.erase(pending_steps_.begin(), pending_steps_.begin() + static_cast<std::ptrdiff_t>(count));
}

void Recorder::write_covered_step_blocks() {
  const std::size_t block = settings_.steps_per_chunk;
  while (pending_steps_.size() >= block && last_tick_written_ && pending_steps_[block - 1].tick <= *last_tick_written_) write_steps(block);
}

void Recorder::write_commands() {
  if (pending_commands_.empty()) return;
  encode_command_block(pending_commands_, payload_);
  writer_.add_chunk(ChunkType::kCommands, payload_, static_cast<std::uint64_t>(std::max<std::int64_t>(0, pending_commands_.front().apply_tick)));
  ++counters_.chunks;
  counters_.commands += pending_commands_.size();
  pending_commands_.clear();
}

void Recorder::write_keyframe(int slot) {
  const SimulationSnapshot& s = keyframe_pool_[static_cast<std::size_t>(slot)];
  const bool topology_changed = s.topology_version != last_topology_version_;
  const bool with_ids = true;  // every keyframe self-contained (see encode_keyframe)
  const auto begin = std::chrono::steady_clock::now();
  const Status encoded = encode_keyframe(std::span(s.node_positions.data(), s.node_count),
                                         std::span(s.surface_triangles.data(), s.surface_triangle_count), header_.grid, settings_.codec,
                                         with_ids, draco_);
  const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - begin).count();
  if (!encoded) {
    note_error(encoded);
    return;
  }
  KeyframeRecord k;
  k.tick = s.tick - 1;  // the collision tick that produced it (s.tick counts the ticks run)
  k.topology_version = s.topology_version;
  k.topology_changed = topology_changed;
  k.has_node_ids = with_ids;
  last_topology_version_ = s.topology_version;
  k.triangle_count = s.surface_triangle_count;
  // The vertices are the nodes the triangles use.
  std::vector<bool>& used = used_nodes_;
  used.assign(s.node_count, false);
  for (std::uint32_t t = 0; t < s.surface_triangle_count; ++t) {
    for (std::uint32_t id : s.surface_triangles[t]) used[id] = true;
  }
  k.vertex_count = static_cast<std::uint32_t>(std::count(used.begin(), used.end(), true));
  k.draco = draco_;
  encode_keyframe_payload(k, payload_);
  writer_.add_chunk(ChunkType::kKeyframe, payload_, k.tick);
  ++counters_.chunks;
  ++counters_.keyframes;
  encode_ms_sum_ += ms;
  counters_.keyframe_encode_ms_max = std::max(counters_.keyframe_encode_ms_max, ms);
}

bool Recorder::drain() {
  // A killed run leaves whatever prefix of the file was written, so a hash must never go out before
  // the ticks that lead to it, nor a tick before its commands. The core pushes commands, then the
  // tick, then the step: taking them in the reverse order means every step taken has its tick
  // taken too, and write_ticks() takes the commands last.
  bool took = false;
  StepRecord step;
  while (steps_.try_pop(step)) {
    pending_steps_.push_back(step);
    took = true;
  }
  TickRecord tick;
  while (ticks_.try_pop(tick)) {
    pending_ticks_.push_back(tick);
    took = true;
    if (pending_ticks_.size() >= settings_.ticks_per_chunk) write_ticks();
  }
  const std::size_t commands_before = pending_commands_.size();
  take_commands();
  took = took || pending_commands_.size() != commands_before;
  write_covered_step_blocks();
  int slot = -1;
  while (filled_slots_.try_pop(slot)) {
    write_keyframe(slot);
    free_slots_.try_push(slot);
    took = true;
  }
  return took;
}

void Recorder::run() {
  using clock = std::chrono::steady_clock;
  auto last_flush = clock::now();
  auto last_sync = last_flush;
  const auto flush_every = std::chrono::duration<double>(settings_.flush_interval_s);
  for (;;) {
    const bool stopping = !running_.load(std::memory_order_acquire);
    const bool took = drain();
    const auto now = clock::now();
    if (stopping || now - last_flush >= flush_every) {
      // Everything held so far goes out, partial blocks included: the file on disk is then at most
      // one flush interval behind the core.
      write_commands();
      write_ticks();
      write_steps(pending_steps_.size());
      note_error(writer_.flush());
      last_flush = now;
      if (now - last_sync >= std::chrono::seconds(1)) {
        note_error(writer_.sync());
        last_sync = now;
      }
    }
    if (stopping && !took) break;
    if (!took) std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
}

Result<RecorderCounters> Recorder::finish(const nlohmann::ordered_json& extra) {
  if (finished_) return Error{"recorder: finished twice"};
  finished_ = true;
  running_.store(false, std::memory_order_release);
  if (thread_.joinable()) thread_.join();
  counters_.ticks_lost = ticks_lost_.load();
  counters_.steps_lost = steps_lost_.load();
  counters_.commands_lost = commands_lost_.load();
  counters_.keyframes_lost = keyframes_lost_.load();
  counters_.keyframe_encode_ms_mean = counters_.keyframes ? encode_ms_sum_ / static_cast<double>(counters_.keyframes) : 0.0;
  nlohmann::ordered_json summary = {
      {"ticks", counters_.ticks},
      {"steps", counters_.steps},
      {"commands", counters_.commands},
      {"keyframes", counters_.keyframes},
      {"lost", {{"ticks", counters_.ticks_lost}, {"steps", counters_.steps_lost}, {"commands", counters_.commands_lost}, {"keyframes", counters_.keyframes_lost}}},
      {"keyframe_encode_ms", {{"mean", counters_.keyframe_encode_ms_mean}, {"max", counters_.keyframe_encode_ms_max}}}};
  if (!extra.is_null()) summary["run"] = extra;
  const std::string text = summary.dump();
  writer_.add_chunk(ChunkType::kSummary, std::span(reinterpret_cast<const std::uint8_t*>(text.data()), text.size()));
  ++counters_.chunks;
  // The writer's error says where the partial recording is, and that the old file is untouched.
  if (Status closed = writer_.close(); !closed) counters_.write_error = closed.error();
  counters_.bytes = writer_.bytes_written();
  if (!counters_.write_error.empty()) return Error{counters_.write_error};
  return counters_;
}

}  // namespace resecto::rec
