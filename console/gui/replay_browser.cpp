// Browsing and verifying a recording in the console.
#include "console/gui/replay_browser.h"

#include <algorithm>

#include "recordings/replay.h"

namespace resecto::gui {

ReplayBrowser::~ReplayBrowser() { close(); }

void ReplayBrowser::close() {
  if (verifier_.joinable()) verifier_.join();
  steps_.reset();
  recording_.reset();
  verifying_.store(false);
  verified_.store(false);
  verification_ = {};
  keyframe_shown_.reset();
}

Status ReplayBrowser::open(const std::filesystem::path& path) {
  Result<rec::Recording> opened = rec::Recording::open(path);
  if (!opened) return Error{opened.error()};  // it names the file
  if (opened->keyframes().empty()) return Error{path.string() + ": the recording holds no keyframe to show"};
  const SimulationConfig& config = opened->header().simulation;
  ProstateModel prostate = generate_prostate(config.prostate_triangles);
  if (opened->header().surface_triangles != prostate.surface.triangle_count()) {
    return Error{path.string() + ": the header says " + std::to_string(opened->header().surface_triangles) + " surface triangles, the gland its settings build has " +
                 std::to_string(prostate.surface.triangle_count()) + ": the header was edited or written by another build"};
  }
  close();
  recording_ = std::make_unique<rec::Recording>(std::move(*opened));
  steps_.emplace(*recording_);
  path_ = path.string();
  tick_s_ = recording_->header().simulation.tick_s();  // `config` went with *opened
  prostate_ = std::move(prostate);
  // Sized once for the largest node id and surface any keyframe can hold.
  snapshot_ = SimulationSnapshot{};
  std::uint32_t max_triangles = recording_->header().surface_triangles;
  for (const rec::KeyframeInfo& k : recording_->keyframes()) max_triangles = std::max(max_triangles, k.triangle_count);
  snapshot_.node_positions.assign(recording_->header().nodes, Vec3(0.0));
  snapshot_.surface_triangles.assign(max_triangles, Triangle{0, 0, 0});
  time_s_ = recording_->keyframes().front().time_s;
  playing_ = false;
  return Ok{};
}

double ReplayBrowser::duration_s() const { return recording_ ? recording_->duration_s() : 0.0; }

void ReplayBrowser::seek(double time_s) {
  if (!recording_) return;
  time_s_ = std::clamp(time_s, 0.0, duration_s());
}

void ReplayBrowser::advance(double dt_s) {
  if (!recording_ || !playing_) return;
  seek(time_s_ + dt_s * speed_);
  if (time_s_ >= duration_s()) playing_ = false;
}

void ReplayBrowser::step() {
  if (!recording_) return;
  playing_ = false;
  const auto keyframes = recording_->keyframes();
  for (const rec::KeyframeInfo& k : keyframes) {
    if (k.time_s > time_s_ + 1e-9) {
      time_s_ = k.time_s;
      return;
    }
  }
}

const SimulationSnapshot& ReplayBrowser::snapshot() {
  if (!recording_) return snapshot_;
  const std::optional<std::size_t> k = recording_->keyframe_at_time(time_s_);
  const std::size_t keyframe = k.value_or(0);
  if (keyframe_shown_ != keyframe) {
    Result<rec::SurfaceFrame> frame = recording_->decode_keyframe(keyframe);
    if (frame) {
      // Vertices come with their mesh node ids: write them where the live snapshot would have them.
      // Refinement adds nodes past the header's count: grow to the largest id this keyframe uses.
      // A keyframe without ids (the format allows it) is drawn with its own vertex numbering.
      const bool ids = frame->node_ids.size() == frame->positions.size();
      auto node_of = [&](std::size_t v) { return ids ? frame->node_ids[v] : static_cast<std::uint32_t>(v); };
      std::size_t needed = 0;
      for (std::size_t v = 0; v < frame->positions.size(); ++v) needed = std::max<std::size_t>(needed, node_of(v) + 1u);
      if (needed > snapshot_.node_positions.size()) snapshot_.node_positions.resize(needed, Vec3(0.0));
      for (std::size_t v = 0; v < frame->positions.size(); ++v) snapshot_.node_positions[node_of(v)] = frame->positions[v];
      const std::size_t count = std::min(frame->triangles.size(), snapshot_.surface_triangles.size());
      for (std::size_t t = 0; t < count; ++t) {
        for (int c = 0; c < 3; ++c) snapshot_.surface_triangles[t][c] = node_of(frame->triangles[t][c]);
      }
      snapshot_.node_count = static_cast<std::uint32_t>(snapshot_.node_positions.size());
      snapshot_.surface_triangle_count = static_cast<std::uint32_t>(count);
      // Draco orders triangles its own way: every decoded keyframe is a new connectivity to upload.
      snapshot_.topology_version = ++topology_counter_;
      keyframe_shown_ = keyframe;
    }
  }
  // The tool and metrics of the collision step at or before the time (60 Hz, finer than keyframes).
  const auto steps = recording_->steps();
  const auto tick = static_cast<std::uint64_t>(std::max(0.0, time_s_ / tick_s_ - 1.0));
  auto after = std::upper_bound(steps.begin(), steps.end(), tick, [](std::uint64_t t, const rec::StepEntry& s) { return t < s.tick; });
  // A step whose chunk no longer reads (the file changed since it was opened) leaves the last one shown.
  if (after != steps.begin()) {
    const auto index = static_cast<std::size_t>(after - 1 - steps.begin());
    if (Result<rec::StepRecord> s = steps_->at(index)) {
      snapshot_.tool = s->tool;
      snapshot_.metrics = s->metrics;
      snapshot_.state_hash = s->state_hash;
      snapshot_.tick = s->tick + 1;
      step_tick_shown_ = s->tick;
      const double pedal_s = s->metrics.cut_pedal_time_s;
      // The step before is nearly always in the chunk just read (45 steps a chunk).
      double before_s = 0.0;
      if (index > 0) {
        if (Result<rec::StepRecord> previous = steps_->at(index - 1)) before_s = previous->metrics.cut_pedal_time_s;
      }
      cutting_shown_ = pedal_s > before_s;
    }
  }
  return snapshot_;
}

double ReplayBrowser::loop_travel_shown_m() const {
  const ToolPoses& tool = snapshot_.tool;
  return dot(tool.loop.translation - tool.sheath.translation, tool.sheath.apply_vector(Vec3(0.0, 0.0, 1.0)));
}

void ReplayBrowser::start_verification() {
  if (!recording_ || verifying_.load() || verified_.load()) return;
  verifying_.store(true, std::memory_order_release);
  const rec::Recording* recording = recording_.get();
  verifier_ = std::thread([this, recording] {
    ReplayVerification result;
    Result<std::unique_ptr<rec::Replayer>> replayer = rec::Replayer::create(*recording);
    if (!replayer) {
      result.error = replayer.error();
    } else {
      rec::Replayer& r = **replayer;
      result.ticks = r.run_to(r.end_tick());
      result.verified = r.verified_hashes();
      result.mismatches = r.mismatches();
      result.first_mismatch_tick = r.first_mismatch_tick();
      result.unverified = rec::unverified_hashes(*recording, r);
      // As `replay --verify` says it: a file with no hash to compare vouches for nothing.
      if (result.verified == 0 && result.mismatches == 0) result.error = recording->name() + ": no collision step's hash could be verified";
    }
    result.done = true;
    verification_ = std::move(result);
    verified_.store(true, std::memory_order_release);
    verifying_.store(false, std::memory_order_release);
  });
}

const ReplayVerification* ReplayBrowser::verification() const {
  return verified_.load(std::memory_order_acquire) ? &verification_ : nullptr;
}

}  // namespace resecto::gui
