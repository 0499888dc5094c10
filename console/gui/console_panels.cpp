// Panel layouts. Figures carry their units; what the core has not applied yet is shown as pending.
#include "console/gui/console_panels.h"

#include <imgui.h>

#include <algorithm>
#include <cinttypes>
#include <cstdio>
#include <filesystem>
#include <string>
#include <system_error>

#include "console/headless/realtime_advice.h"
#include "rtcore/base/units.h"

namespace resecto::gui {
namespace {

const char* input_state_name(ToolInputState state) {
  switch (state) {
    case ToolInputState::kNoDevice: return "no device yet";
    case ToolInputState::kTracking: return "tracking";
    case ToolInputState::kFrozen: return "frozen (disconnected)";
    case ToolInputState::kReengaging: return "re-engaging";
  }
  return "?";
}

constexpr double kSpeeds[] = {1.0, 0.5, 0.25, 0.125, 1.0 / 16.0};
constexpr const char* kSpeedNames[] = {"1x (real time)", "1/2", "1/4", "1/8", "1/16"};

/// A row of a two-column table: label, then formatted text.
template <class... Args>
void row(const char* label, const char* format, Args... args) {
  ImGui::TableNextRow();
  ImGui::TableSetColumnIndex(0);
  ImGui::TextUnformatted(label);
  ImGui::TableSetColumnIndex(1);
  ImGui::Text(format, args...);
}

/// A message line in a colour, wrapped at the panel's edge rather than cut off there (audit 11).
template <class... Args>
void wrapped_colored(const ImVec4& colour, const char* format, Args... args) {
  ImGui::PushStyleColor(ImGuiCol_Text, colour);
  ImGui::TextWrapped(format, args...);
  ImGui::PopStyleColor();
}

const ImVec4 kWarning(1.0f, 0.5f, 0.3f, 1.0f);

/// Said while the recording is made, not first when `resecto score` refuses it (audit 11).
void mid_session_note(std::uint64_t start_tick) {
  wrapped_colored(kWarning, "recorded %s", mid_session_recording_note(start_tick).c_str());
}

/// Resection's figures in the debrief's words and units (strokes, not collision steps), so the
/// panel and the page a trainee reads later agree.
void resection_rows(const ProcedureMetrics& m) {
  const auto plural = [](std::uint64_t n) { return n == 1 ? "" : "s"; };
  row("resected", "%.2f g (adenoma %.2f g, capsule %.2f g)", m.resected_total_g, m.resected_adenoma_g, m.resected_capsule_g);
  row("cuts", "%" PRIu64 " stroke%s, %" PRIu64 " chip%s (%.2f g)", m.cuts, plural(m.cuts), m.chips, plural(m.chips), m.chips_g);
  row("perforations", "%" PRIu64 " stroke%s", m.perforations, plural(m.perforations));
  row("sphincter zone", "%" PRIu64 " stroke%s, %.2f s cutting distal to the verumontanum", m.sphincter_zone_violations,
      plural(m.sphincter_zone_violations), m.sphincter_zone_cut_s);
}

}  // namespace

std::string mid_session_recording_note(std::uint64_t start_tick) {
  return "from tick " + std::to_string(start_tick) +
         " (mid-session): it replays in the console, but `resecto score` and `replay --verify` need a session recorded from its "
         "first tick (--record FILE)";
}

void draw_simulation_panel(ConsoleController& console) {
  const LiveFrame& f = console.frame();
  const CoreStatus& s = f.status;
  ConsoleUi& ui = console.ui();
  const double tick_s = console.session().simulation().config().tick_s();
  const bool diverged = f.snapshot.metrics.non_finite_steps > 0;
  const char* verdict = diverged ? "diverged" : (s.paused ? "paused" : "ok");
  ImGui::Text("tick %" PRIu64 "  (%.3f s)   state %s   hash %016" PRIx64, s.next_tick, static_cast<double>(s.next_tick) * tick_s, verdict,
              f.snapshot.state_hash);
  if (s.paused) {
    if (ImGui::Button("Resume (P)")) console.resume();
  } else {
    if (ImGui::Button("Pause (P)")) console.pause();
  }
  ImGui::SameLine();
  ImGui::BeginDisabled(!s.paused);
  if (ImGui::Button("Step (N)")) console.step(1);
  ImGui::SameLine();
  if (ImGui::Button("Step 1 collision")) console.step(static_cast<std::uint32_t>(console.session().simulation().config().physics_per_collision));
  ImGui::SameLine();
  ImGui::SetNextItemWidth(80);
  ImGui::InputInt("##batch", &ui.batch_steps, 0);
  ui.batch_steps = std::clamp(ui.batch_steps, 1, 1000000);
  ImGui::SameLine();
  if (ImGui::Button("Run batch")) console.step(static_cast<std::uint32_t>(ui.batch_steps));
  ImGui::EndDisabled();
  if (s.pending_steps > 0) ImGui::Text("stepping: %" PRIu64 " ticks to go", s.pending_steps);
  ImGui::SetNextItemWidth(160);
  if (ImGui::Combo("speed", &ui.speed_index, kSpeedNames, IM_ARRAYSIZE(kSpeedNames))) console.set_speed(kSpeeds[ui.speed_index]);
  ImGui::SameLine();
  ImGui::Text("core at %.3gx", s.speed);
  if (!ui.message.empty()) wrapped_colored(kWarning, "%s", ui.message.c_str());
}

void draw_parameter_panel(ConsoleController& console) {
  const CoreStatus& s = console.frame().status;
  ConsoleUi& ui = console.ui();
  ImGui::TextDisabled("a change applies at the core's next tick; 'in force' is what the core uses");
  for (const TissueParameterSpec& spec : tissue_parameter_specs()) {
    const auto p = static_cast<std::size_t>(spec.id);
    double value = ui.slider_values[p];
    const std::string label = std::string(spec.key) + " (" + std::string(spec.unit) + ")";
    ImGui::SetNextItemWidth(200);
    const ImGuiSliderFlags flags = spec.min_value > 0.0 && spec.max_value / spec.min_value > 50.0 ? ImGuiSliderFlags_Logarithmic : 0;
    const bool changed = ImGui::SliderScalar(label.c_str(), ImGuiDataType_Double, &value, &spec.min_value, &spec.max_value, "%.4g", flags);
    if (ImGui::IsItemHovered()) ImGui::SetTooltip("%s\nrange %g .. %g %s", std::string(spec.description).c_str(), spec.min_value,
                                                  spec.max_value, std::string(spec.unit).c_str());
    if (changed) console.set_parameter(spec.id, value);
    ImGui::SameLine();
    const double in_force = s.parameters.get(spec.id);
    if (s.applied_tick[p] >= 0) {
      ImGui::TextDisabled("in force %.4g, since tick %" PRId64, in_force, s.applied_tick[p]);
    } else {
      ImGui::TextDisabled("in force %.4g", in_force);
    }
  }
  ImGui::SetNextItemWidth(220);
  char path[512];
  std::snprintf(path, sizeof path, "%s", ui.preset_path.c_str());
  if (ImGui::InputText("preset file", path, sizeof path)) ui.preset_path = path;
  if (ImGui::Button("Save preset")) (void)console.save_preset(ui.preset_path);
  ImGui::SameLine();
  if (ImGui::Button("Load preset")) (void)console.load_preset(ui.preset_path);
  ImGui::SameLine();
  if (ImGui::Button("Defaults")) console.request_parameters(TissueParameters{});
  if (!ui.preset_message.empty()) wrapped_colored(ImGui::GetStyleColorVec4(ImGuiCol_TextDisabled), "%s", ui.preset_message.c_str());
}

void draw_device_panel(ConsoleController& console) {
  const CoreStatus& s = console.frame().status;
  ConsoleUi& ui = console.ui();
  LiveDevice* live = console.session().live_device();
  if (ImGui::BeginTable("device", 2, ImGuiTableFlags_SizingStretchProp)) {
    row("transport", "%s", console.session().device_description().c_str());
    if (live) {
      const LinkCounters c = live->link().published_counters();
      row("connection", "%s", live->link().connected() ? "connected" : "not connected");
      row("rate", "%.0f Hz", c.rate_hz);
      row("reports / lost", "%" PRIu64 " / %" PRIu64, c.reports, c.lost);
      row("rejected / dup.", "%" PRIu64 " / %" PRIu64, c.rejected, c.duplicates);
      row("latency", "median %.0f us, p99 %.0f us", c.latency_median_us, c.latency_p99_us);
      // A flagged encoder has lost counts: its angle below is off from then on.
      const BoardFlagCounts& f = c.board_flags;
      row("encoder faults", "yaw %" PRIu64 ", pitch %" PRIu64 ", roll %" PRIu64, f.illegal_transitions[0], f.illegal_transitions[1],
          f.illegal_transitions[2]);
    } else {
      row("connection", "lockstep (stepped with the core)");
      row("reports / lost", "%" PRIu64 " / %" PRIu64, s.lockstep_reports, s.lockstep_lost);
    }
    row("input", "%s", input_state_name(s.input_state));
    row("yaw", "%+7.2f deg", units::rad_to_deg(s.joints.yaw_rad));
    row("pitch", "%+7.2f deg", units::rad_to_deg(s.joints.pitch_rad));
    row("roll", "%+7.2f deg", units::rad_to_deg(s.joints.roll_rad));
    row("insertion", "%7.2f mm", units::m_to_mm(s.joints.insertion_m));
    row("loop", "%7.2f mm", units::m_to_mm(s.joints.loop_travel_m));
    row("pedals", "cut %s   coag %s", (s.pedals & kPedalCut) ? "DOWN" : "up", (s.pedals & kPedalCoagulate) ? "DOWN" : "up");
    ImGui::EndTable();
  }
  if (console.manual_device()) {
    ImGui::Separator();
    ImGui::TextDisabled("drive: W/S insert, A/D yaw, R/F pitch, Q/E roll, X/Z loop, Space cut, C coag;");
    ImGui::TextDisabled("drag the endoscope image to steer, wheel to insert; %s",
                        ui.gamepad_present ? ui.gamepad_name.c_str() : "no gamepad");
    firmware::MotionState m = ui.manual.state();
    double yaw = units::rad_to_deg(m.yaw_rad), pitch = units::rad_to_deg(m.pitch_rad), roll = units::rad_to_deg(m.roll_rad);
    bool changed = false;
    ImGui::SetNextItemWidth(200);
    changed |= ImGui::DragScalar("yaw (deg)", ImGuiDataType_Double, &yaw, 0.2f);
    ImGui::SetNextItemWidth(200);
    changed |= ImGui::DragScalar("pitch (deg)", ImGuiDataType_Double, &pitch, 0.2f);
    ImGui::SetNextItemWidth(200);
    changed |= ImGui::DragScalar("roll (deg)", ImGuiDataType_Double, &roll, 0.5f);
    ImGui::SetNextItemWidth(200);
    changed |= ImGui::DragScalar("insertion (mm)", ImGuiDataType_Double, &m.insertion_mm, 0.2f);
    ImGui::SetNextItemWidth(200);
    changed |= ImGui::DragScalar("loop (mm)", ImGuiDataType_Double, &m.loop_mm, 0.1f);
    if (changed) {
      (void)console.set_by_key("yaw", yaw);
      (void)console.set_by_key("pitch", pitch);
      (void)console.set_by_key("roll", roll);
      (void)console.set_by_key("insertion", m.insertion_mm);
      (void)console.set_by_key("loop", m.loop_mm);
    }
  }
}

void draw_metrics_panel(ConsoleController& console) {
  const LiveFrame& f = console.frame();
  const ProcedureMetrics& m = f.snapshot.metrics;
  if (!ImGui::BeginTable("metrics", 2, ImGuiTableFlags_SizingStretchProp)) return;
  row("contact now", "%d points, %.2f N", f.snapshot.penetrating_points, length(f.snapshot.reaction.force_n));
  row("contact time", "%.2f s", m.contact_time_s);
  row("force", "peak %.2f N, mean %.2f N", m.peak_reaction_force_n, m.mean_contact_force_n);
  row("cut pedal", "%.2f s down, %.2f s of it cutting nothing", m.cut_pedal_time_s, m.loop_on_idle_s);
  row("tissue moved", "up to %.2f mm", m.max_tissue_displacement_mm);
  row("deepest insertion", "%.1f mm", m.max_insertion_mm);
  if (!m.distal_margin_mm) {
    row("verumontanum margin", "no cut yet");
  } else {
    row("verumontanum margin", "%.1f mm at the least (+ proximal)", *m.distal_margin_mm);
  }
  resection_rows(m);
  row("faults", "%" PRIu64 " non-finite, %" PRIu64 " contact overflows", m.non_finite_steps, m.contact_overflows);
  row("fast motion", "%" PRIu64 " ticks beyond the contact margin", m.contact_margin_exceeded_ticks);
  row("surface", "%u triangles, topology v%" PRIu64, f.snapshot.surface_triangle_count, f.snapshot.topology_version);
  ImGui::EndTable();
}

void draw_profiler_panel(ConsoleController& console) {
  const CoreStatus& s = console.frame().status;
  ConsoleUi& ui = console.ui();
  ImGui::Text("deadlines: %" PRIu64 " missed of %" PRIu64 " ticks (%.3f%%), worst %.0f us late, %" PRIu64 " re-anchorings; core %s",
              s.deadline_misses, s.deadline_ticks,
              s.deadline_ticks ? 100.0 * static_cast<double>(s.deadline_misses) / static_cast<double>(s.deadline_ticks) : 0.0,
              s.max_late_us, s.resynchronizations, console.session().realtime_priority_held() ? "SCHED_FIFO" : "normal priority");
  // Once a second of ticks has run, a machine too slow for the rate is told what would fit.
  const Simulation& sim = console.session().simulation();
  if (s.deadline_ticks >= static_cast<std::uint64_t>(sim.config().collision_hz * sim.config().physics_per_collision)) {
    const std::string advice = realtime_advice(realtime_figures(sim, static_cast<double>(s.deadline_misses) / static_cast<double>(s.deadline_ticks),
                                                                s.p99_us[static_cast<std::size_t>(Stage::kTick)]));
    if (!advice.empty()) {
      ImGui::PushStyleColor(ImGuiCol_Text, ImVec4(1.0f, 0.75f, 0.3f, 1.0f));
      ImGui::TextWrapped("%s", advice.c_str());
      ImGui::PopStyleColor();
    }
  }
  ImGui::Text("frame: median %.1f ms, p99 %.1f ms   input-to-photon: median %.1f ms, p99 %.1f ms (%" PRIu64 " frames)",
              ui.frame_ms_as_us.quantile(0.5) * 1e-3, ui.frame_ms_as_us.quantile(0.99) * 1e-3,
              ui.input_to_photon_us.quantile(0.5) * 1e-3, ui.input_to_photon_us.quantile(0.99) * 1e-3, ui.input_to_photon_us.count());
  // The stage plots: the worst tick of each collision step over the last ten seconds, budget in red.
  const float plot_width = std::max(120.0f, (ImGui::GetContentRegionAvail().x - 16.0f) / 3.0f);
  std::array<float, kStageHistoryLength> ordered{};
  const std::size_t n = s.history_count;
  for (int st = 0; st < kStageCount; ++st) {
    const auto& h = s.history_us[static_cast<std::size_t>(st)];
    const std::size_t start = n < kStageHistoryLength ? 0 : s.history_next;
    for (std::size_t i = 0; i < n; ++i) ordered[i] = h[(start + i) % kStageHistoryLength];
    const float budget = static_cast<float>(s.budget_us[static_cast<std::size_t>(st)]);
    float top = budget * 1.5f;
    for (std::size_t i = 0; i < n; ++i) top = std::max(top, ordered[i]);
    char overlay[160];
    std::snprintf(overlay, sizeof overlay, "%s  med %.0f p99 %.0f / %.0f us  over %" PRIu64, stage_name(static_cast<Stage>(st)),
                  s.median_us[static_cast<std::size_t>(st)], s.p99_us[static_cast<std::size_t>(st)], budget,
                  s.over_budget[static_cast<std::size_t>(st)]);
    if (st % 3 != 0) ImGui::SameLine();
    ImGui::PlotLines(("##stage" + std::to_string(st)).c_str(), ordered.data(), static_cast<int>(n), 0, overlay, 0.0f, top,
                     ImVec2(plot_width, 70.0f));
    const ImVec2 lo = ImGui::GetItemRectMin(), hi = ImGui::GetItemRectMax();
    const float y = hi.y - (hi.y - lo.y) * (budget / top);
    ImGui::GetWindowDrawList()->AddLine(ImVec2(lo.x, y), ImVec2(hi.x, y), IM_COL32(255, 70, 60, 220), 1.5f);
  }
  std::array<float, 240> frames{};
  for (std::size_t i = 0; i < frames.size(); ++i) frames[i] = ui.frame_history_ms[(ui.frame_history_next + i) % frames.size()];
  ImGui::PlotLines("##frames", frames.data(), static_cast<int>(frames.size()), 0, "console frame time (ms), last 240 frames", 0.0f,
                   std::max(50.0f, *std::max_element(frames.begin(), frames.end())), ImVec2(ImGui::GetContentRegionAvail().x, 60.0f));
}

void draw_recording_panel(ConsoleController& console) {
  const CoreStatus& s = console.frame().status;
  ConsoleUi& ui = console.ui();
  if (s.recording) {
    // The partial file grows as the recorder thread flushes (twice a second); its size is the disk's
    // word. The target is replaced only when the recording is closed.
    std::error_code error;
    const auto bytes = std::filesystem::file_size(s.recording_partial_path.data(), error);
    if (!error) ui.recording_bytes_seen = bytes;
    const double seconds = static_cast<double>(FrameProfiler::now_ns() - ui.recording_started_ns) * 1e-9;
    const double simulated_s = static_cast<double>(s.next_tick - s.recording_start_tick) * console.session().simulation().config().tick_s();
    ImGui::TextColored(ImVec4(1.0f, 0.3f, 0.3f, 1.0f), "REC");
    ImGui::SameLine();
    ImGui::Text("%s", s.recording_path.data());
    ImGui::Text("%.2f MB, %.0f kB/s, %.1f s simulated since tick %" PRIu64 ", %" PRIu64 " records lost",
                static_cast<double>(ui.recording_bytes_seen) / 1e6, seconds > 0 ? static_cast<double>(ui.recording_bytes_seen) / seconds / 1e3 : 0.0,
                simulated_s, s.recording_start_tick, s.recording_lost);
    if (s.recording_start_tick > 0) mid_session_note(s.recording_start_tick);
    if (ImGui::Button("Stop recording")) console.stop_recording();
  } else {
    char path[512];
    std::snprintf(path, sizeof path, "%s", ui.record_path.c_str());
    ImGui::SetNextItemWidth(260);
    if (ImGui::InputText("file##record", path, sizeof path)) ui.record_path = path;
    ImGui::SameLine();
    // A path that cannot be written is named below rather than left for the core to fail on.
    if (ImGui::Button("Record")) {
      const Status started = console.start_recording(ui.record_path);
      ui.record_message = started ? std::string() : started.error();
    }
    if (!ui.record_message.empty()) wrapped_colored(kWarning, "%s", ui.record_message.c_str());
    if (s.recordings_finished > 0) {
      ImGui::TextDisabled("last: %s, %.2f MB, %" PRIu64 " ticks, %" PRIu64 " keyframes, %" PRIu64 " lost", s.recording_path.data(),
                          static_cast<double>(s.recorded_bytes) / 1e6, s.recorded_ticks, s.recorded_keyframes, s.recording_lost);
      if (s.recording_start_tick > 0) mid_session_note(s.recording_start_tick);
    } else if (s.next_tick > 0) {
      wrapped_colored(ImGui::GetStyleColorVec4(ImGuiCol_TextDisabled), "Record starts at the next tick; a session to be scored needs --record FILE, from tick 0");
    }
  }
  if (s.recording_message[0] != '\0') wrapped_colored(kWarning, "%s", s.recording_message.data());
}

void draw_replay_panel(ConsoleController& console) {
  ConsoleUi& ui = console.ui();
  ReplayBrowser& replay = ui.replay;
  char path[512];
  std::snprintf(path, sizeof path, "%s", ui.replay_path.c_str());
  ImGui::SetNextItemWidth(260);
  if (ImGui::InputText("file##replay", path, sizeof path)) ui.replay_path = path;
  ImGui::SameLine();
  if (ImGui::Button("Open")) (void)console.open_replay(ui.replay_path);
  if (!ui.replay_message.empty()) wrapped_colored(ImGui::GetStyleColorVec4(ImGuiCol_TextDisabled), "%s", ui.replay_message.c_str());
  if (!replay.is_open()) return;
  const rec::Recording& r = replay.recording();
  ImGui::TextWrapped("%s: %s, %.1f s, %zu keyframes, %zu steps, procedure '%s'", replay.path().c_str(), r.header().mode.c_str(),
                     replay.duration_s(), r.keyframes().size(), r.steps().size(), r.header().procedure.c_str());
  ImGui::Checkbox("show the replay in the views", &ui.show_replay);
  if (replay.playing()) {
    if (ImGui::Button("Pause##replay")) replay.pause();
  } else {
    if (ImGui::Button("Play##replay")) {
      replay.play();
      ui.show_replay = true;
    }
  }
  ImGui::SameLine();
  if (ImGui::Button("Step##replay")) replay.step();
  ImGui::SameLine();
  float speed = static_cast<float>(replay.speed());
  ImGui::SetNextItemWidth(100);
  if (ImGui::SliderFloat("speed##replay", &speed, static_cast<float>(ReplayBrowser::kMinSpeed), static_cast<float>(ReplayBrowser::kMaxSpeed),
                         "%.2fx", ImGuiSliderFlags_Logarithmic)) {
    replay.set_speed(speed);
  }
  ImGui::SameLine();
  ImGui::BeginDisabled(replay.verifying());
  if (ImGui::Button(replay.verifying() ? "Verifying..." : "Verify")) replay.start_verification();
  ImGui::EndDisabled();
  float t = static_cast<float>(replay.time_s());
  ImGui::SetNextItemWidth(-1);
  if (ImGui::SliderFloat("##timeline", &t, 0.0f, static_cast<float>(replay.duration_s()), "%.2f s")) {
    replay.seek(t);
    ui.show_replay = true;
  }
  if (replay.keyframe_shown()) {
    // The recording's own keyframe number (a lost keyframe keeps its number), as `rec export` takes it.
    ImGui::TextDisabled("keyframe %" PRIu64 " (at %.2f s), tool at collision step tick %" PRIu64, *replay.keyframe_number_shown(),
                        r.keyframes()[*replay.keyframe_shown()].time_s, replay.step_tick_shown());
  }
  if (const ReplayVerification* v = replay.verification()) {
    if (!v->error.empty()) {
      wrapped_colored(kWarning, "verify: %s", v->error.c_str());
    } else if (v->mismatches == 0 && !v->unverified.empty()) {
      wrapped_colored(kWarning, "%" PRIu64 " hashes match, but not the whole recording: %s", v->verified, v->unverified.c_str());
    } else if (v->mismatches == 0) {
      ImGui::TextColored(ImVec4(0.4f, 1.0f, 0.4f, 1.0f), "verified: %" PRIu64 " of %" PRIu64 " hashes match (%" PRIu64 " ticks)", v->verified,
                         v->verified, v->ticks);
    } else {
      ImGui::TextColored(ImVec4(1.0f, 0.3f, 0.3f, 1.0f), "%" PRIu64 " hashes differ, first at tick %" PRIu64, v->mismatches,
                         v->first_mismatch_tick.value_or(0));
    }
  }
}

}  // namespace resecto::gui
