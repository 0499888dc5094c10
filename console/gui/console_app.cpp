// The console's window and frame loop: input, scripted actions, the two views, the panels, and the
// session's report. Index: options and setup (run_console), one frame (ConsoleWindow::frame), the
// actions (apply_action), the report (make_report, summarize_console_report).
#include "console/gui/console_app.h"

// clang-format off
#include "console/gui/gl_api.h"
#include <GLFW/glfw3.h>
// clang-format on
#include <imgui.h>
#include <backends/imgui_impl_glfw.h>
#include <backends/imgui_impl_opengl3.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cinttypes>
#include <cmath>
#include <cstdlib>
#include <thread>
#include <vector>

#include "console/gui/console_controller.h"
#include "console/gui/console_panels.h"
#include "console/gui/scene_renderer.h"
#include "console/gui/screenshot.h"
#include "console/headless/headless_run.h"
#include "console/headless/realtime_advice.h"
#include "console/live/interrupt.h"
#include "rtcore/base/atomic_file.h"
#include "rtcore/base/units.h"
#include "rtcore/core/thread_priority.h"

namespace resecto::gui {
namespace {

using nlohmann::ordered_json;

std::string g_glfw_error;
void on_glfw_error(int code, const char* description) { g_glfw_error = "GLFW error " + std::to_string(code) + ": " + description; }

std::int64_t now_ns() { return FrameProfiler::now_ns(); }

/// The GLFW key a script names: a letter, a digit, or SPACE (script_key_known()).
int key_code(const std::string& name) {
  if (name.size() == 1 && name[0] >= 'A' && name[0] <= 'Z') return GLFW_KEY_A + (name[0] - 'A');
  if (name.size() == 1 && name[0] >= 'a' && name[0] <= 'z') return GLFW_KEY_A + (name[0] - 'a');
  if (name.size() == 1 && name[0] >= '0' && name[0] <= '9') return GLFW_KEY_0 + (name[0] - '0');
  if (name == "SPACE" || name == "space") return GLFW_KEY_SPACE;
  return -1;
}

/// Owns the window, ImGui and the renderer for one session.
class ConsoleWindow {
 public:
  ConsoleWindow(GLFWwindow* window, const ConsoleOptions& options, CoreSession& session, SceneRenderer& renderer,
                std::vector<Action> actions)
      : window_(window), options_(options), session_(session), renderer_(renderer), settings_(options.settings),
        controller_(session, ui_, settings_), actions_(std::move(actions)) {
    ui_.manual = ManualMotion(options.core.device.manual_start);
    controller_.protect_inputs(options.input_paths);
    controller_.claim_output(options.report_path, OutputKind::kReport);
    controller_.claim_output(options.screenshot_path, OutputKind::kScreenshot);
    controller_.claim_output(options.trace_path, OutputKind::kTrace);
    // The frames for --trace, the last ones in a ring as the core's stages are (a frame is ~50 ms
    // here; this holds hours of them).
    if (!options.trace_path.empty()) frame_spans_.resize(kTracedFrames);
    // Checked with the other outputs before the window opened (open_console): it starts.
    if (!options.record_path.empty()) (void)controller_.start_recording(options.record_path);
    for (const TissueParameterSpec& spec : tissue_parameter_specs()) {
      ui_.slider_values[static_cast<std::size_t>(spec.id)] = settings_.parameters.get(spec.id);
    }
  }

  /// Runs frames until the window closes, a quit action, or --frames; an error from a bad action.
  Status run();
  /// Opens --replay's recording before the first frame.
  Status open_initial_replay() { return options_.replay_path.empty() ? Status(Ok{}) : controller_.open_replay(options_.replay_path); }
  ConsoleUi& ui() { return ui_; }
  /// The frames drawn, oldest first, as the trace's spans (the last kTracedFrames; none without --trace).
  std::vector<TraceSpan> traced_frames() const;

 private:
  static constexpr std::size_t kTracedFrames = std::size_t{1} << 18;
  Status apply_action(const Action& action);
  Status account_for_unrun_actions() const;
  void read_manual_input(double dt_s);
  /// Chooses what the views show and brings its renderer up to date.
  Status choose_shown(bool fresh_live_frame);
  void layout_and_draw();
  void draw_endoscope_window(const ImVec2& pos, const ImVec2& size);
  void draw_outside_window(const ImVec2& pos, const ImVec2& size);
  /// The landmarks' names beside their markers in the outside view, none over another.
  void draw_landmark_labels(ImDrawList* draw, const ImVec2& origin, const CameraView& camera, float w, float h) const;
  int scaled(int pixels) const { return std::max(16, static_cast<int>(std::lround(pixels * options_.view_scale))); }
  bool slowed(std::uint64_t frame) const { return options_.slow_frame_ms > 0.0 && (frame + 1) % options_.slow_frame_every == 0; }

  GLFWwindow* window_;
  const ConsoleOptions& options_;
  CoreSession& session_;
  SceneRenderer& renderer_;
  ConsoleSettings settings_;
  ConsoleUi ui_;
  ConsoleController controller_;
  std::vector<Action> actions_;
  std::size_t next_action_ = 0;
  RenderTarget endoscope_target_, outside_target_;
  // What the views show this frame: the live core's snapshot, or the replay's.
  const SimulationSnapshot* shown_ = nullptr;
  SceneRenderer* scene_ = nullptr;
  std::unique_ptr<SceneRenderer> replay_renderer_;
  std::string replay_renderer_path_;
  std::vector<std::string> screenshots_due_;
  bool quit_ = false;
  bool have_frame_ = false;
  std::vector<TraceSpan> frame_spans_;  // a ring: frame n at n % size
};

std::vector<TraceSpan> ConsoleWindow::traced_frames() const {
  std::vector<TraceSpan> frames;
  if (frame_spans_.empty()) return frames;
  const std::uint64_t drawn = ui_.frame, kept = std::min<std::uint64_t>(drawn, frame_spans_.size());
  for (std::uint64_t n = drawn - kept; n < drawn; ++n) frames.push_back(frame_spans_[n % frame_spans_.size()]);
  return frames;
}

Status ConsoleWindow::apply_action(const Action& a) {
  const std::string where = options_.actions_path + ":" + std::to_string(a.line) + ":" + std::to_string(a.column) + ": ";
  auto fail = [&](const std::string& message) -> Status { return Error{where + message}; };
  switch (a.verb) {
    case ActionVerb::kSet:
      if (Status set = controller_.set_by_key(a.words[0], a.value); !set) return fail(set.error());
      break;
    case ActionVerb::kPedal:
      if (!controller_.manual_device()) return fail("pedal: the pedals follow the device; start with --device keyboard");
      (a.words[0] == "cut" ? ui_.script_cut : ui_.script_coagulate) = a.words[1] == "on";
      break;
    case ActionVerb::kKey: {
      const int code = key_code(a.words[0]);
      if (code < 0) return fail("key: '" + a.words[0] + "' is not a key (a letter, a digit or SPACE)");
      ui_.script_keys[static_cast<std::size_t>(code)] = a.words[1] == "down";
      break;
    }
    case ActionVerb::kDrag:
      if (a.words[0] == "outside") {
        ui_.orbit.drag(static_cast<float>(a.value), static_cast<float>(a.value2));
      } else {
        if (!controller_.manual_device()) return fail("drag endoscope steers the hand-driven device; start with --device keyboard");
        controller_.drag_endoscope(static_cast<float>(a.value), static_cast<float>(a.value2));
      }
      break;
    case ActionVerb::kPause: controller_.pause(); break;
    case ActionVerb::kResume: controller_.resume(); break;
    case ActionVerb::kStep: controller_.step(static_cast<std::uint32_t>(a.value)); break;
    case ActionVerb::kRecord:
      if (a.words[0] == "stop") {
        controller_.stop_recording();
      } else if (Status started = controller_.start_recording(a.words[0]); !started) {
        return fail(started.error());
      }
      break;
    case ActionVerb::kReplay:
      if (a.words[0] == "open") {
        if (Status opened = controller_.open_replay(a.words[1]); !opened) return fail(opened.error());
      } else if (Status done = controller_.replay_operation(a.words[0], a.value); !done) {
        return fail(done.error());
      }
      break;
    case ActionVerb::kScreenshot:
      if (Status writable = controller_.check_output(a.words[0], OutputKind::kScreenshot); !writable) return fail(writable.error());
      controller_.claim_output(a.words[0], OutputKind::kScreenshot);
      screenshots_due_.push_back(a.words[0]);
      break;
    case ActionVerb::kPreset:
      if (Status done = a.words[0] == "save" ? controller_.save_preset(a.words[1]) : controller_.load_preset(a.words[1]); !done) {
        return fail(done.error());
      }
      break;
    case ActionVerb::kQuit: quit_ = true; break;
  }
  return Ok{};
}

void ConsoleWindow::read_manual_input(double dt_s) {
  ManualFollower* follower = session_.live_device() ? session_.live_device()->manual() : nullptr;
  if (!follower) return;
  const bool keyboard_free = !ImGui::GetIO().WantCaptureKeyboard;
  ManualCommand command = command_from_keys([&](int key) {
    return ui_.script_keys[static_cast<std::size_t>(key)] || (keyboard_free && glfwGetKey(window_, key) == GLFW_PRESS);
  });
  ManualCommand pad;
  ui_.gamepad_present = poll_gamepad(GLFW_JOYSTICK_1, pad);
  if (ui_.gamepad_present) {
    const char* name = glfwGetGamepadName(GLFW_JOYSTICK_1);
    ui_.gamepad_name = name ? name : "gamepad";
    // The larger request on each axis wins: keys and sticks can be used together.
    auto pick = [](double a, double b) { return std::abs(a) >= std::abs(b) ? a : b; };
    command.yaw = pick(command.yaw, pad.yaw);
    command.pitch = pick(command.pitch, pad.pitch);
    command.roll = pick(command.roll, pad.roll);
    command.insertion = pick(command.insertion, pad.insertion);
    command.loop = pick(command.loop, pad.loop);
    command.cut |= pad.cut;
    command.coagulate |= pad.coagulate;
  }
  command.cut |= ui_.script_cut;
  command.coagulate |= ui_.script_coagulate;
  ui_.manual.apply(command, dt_s);
  follower->publish(ui_.manual.state());
}

void ConsoleWindow::draw_endoscope_window(const ImVec2& pos, const ImVec2& size) {
  ImGui::SetNextWindowPos(pos);
  ImGui::SetNextWindowSize(size);
  ImGui::PushStyleVar(ImGuiStyleVar_WindowPadding, ImVec2(0, 0));
  ImGui::Begin("Endoscope (30 deg lens)", nullptr, ImGuiWindowFlags_NoMove | ImGuiWindowFlags_NoResize | ImGuiWindowFlags_NoCollapse |
                                                        ImGuiWindowFlags_NoScrollbar);
  const ImVec2 avail = ImGui::GetContentRegionAvail();
  const int w = std::max(16, static_cast<int>(avail.x)), h = std::max(16, static_cast<int>(avail.y));
  endoscope_target_.resize(scaled(w), scaled(h), 0);
  const LiveFrame& f = controller_.frame();
  const CameraView camera = endoscope_camera(shown_->tool.sheath, ui_.lens, static_cast<float>(w) / static_cast<float>(h));
  scene_->draw_endoscope(endoscope_target_, camera);
  const ImVec2 origin = ImGui::GetCursorScreenPos();
  ImGui::Image(reinterpret_cast<ImTextureID>(static_cast<std::intptr_t>(endoscope_target_.texture())), ImVec2(float(w), float(h)),
               ImVec2(0, 1), ImVec2(1, 0));
  ui_.endoscope_rect = {origin.x, origin.y, float(w), float(h)};
  if (ImGui::IsItemHovered() && controller_.manual_device()) {
    const ImGuiIO& io = ImGui::GetIO();
    if (ImGui::IsMouseDragging(ImGuiMouseButton_Left)) controller_.drag_endoscope(io.MouseDelta.x, io.MouseDelta.y);
    if (io.MouseWheel != 0.0f) {
      (void)controller_.set_by_key("insertion", ui_.manual.state().insertion_mm + io.MouseWheel);
    }
  }
  ImDrawList* draw = ImGui::GetWindowDrawList();
  char text[160];
  if (shown_ != &f.snapshot) {
    // The replay's pose, as the recording has it (the live core keeps running behind it).
    const Vec3 tip = shown_->tool.sheath.translation;
    std::snprintf(text, sizeof text, "REPLAY %.2f s (keyframe %llu)  loop %.1f mm  sheath tip %.1f %.1f %.1f mm", ui_.replay.time_s(),
                  static_cast<unsigned long long>(ui_.replay.keyframe_number_shown().value_or(0)),
                  units::m_to_mm(ui_.replay.loop_travel_shown_m()), units::m_to_mm(tip.x), units::m_to_mm(tip.y), units::m_to_mm(tip.z));
    draw->AddText(ImVec2(origin.x + 8, origin.y + 6), IM_COL32(120, 220, 255, 255), text);
    if (ui_.replay.cutting_shown()) draw->AddText(ImVec2(origin.x + 8, origin.y + 24), IM_COL32(255, 200, 40, 255), "CUT");
  } else {
    std::snprintf(text, sizeof text, "roll %+.0f deg  insertion %.1f mm  loop %.1f mm", units::rad_to_deg(f.status.joints.roll_rad),
                  units::m_to_mm(f.status.joints.insertion_m), units::m_to_mm(f.status.joints.loop_travel_m));
    draw->AddText(ImVec2(origin.x + 8, origin.y + 6), IM_COL32(230, 230, 230, 255), text);
    if (f.status.pedals & kPedalCut) draw->AddText(ImVec2(origin.x + 8, origin.y + 24), IM_COL32(255, 200, 40, 255), "CUT");
    if (f.status.pedals & kPedalCoagulate) draw->AddText(ImVec2(origin.x + 48, origin.y + 24), IM_COL32(80, 160, 255, 255), "COAG");
  }
  if (f.status.paused) draw->AddText(ImVec2(origin.x + 8, origin.y + float(h) - 22), IM_COL32(255, 255, 255, 255), "PAUSED");
  ImGui::End();
  ImGui::PopStyleVar();
}

void ConsoleWindow::draw_landmark_labels(ImDrawList* draw, const ImVec2& origin, const CameraView& camera, float w, float h) const {
  // Landmarks a few millimetres apart (the apex and the external sphincter) project onto one spot from
  // most orbits: each label, top to bottom, is moved down below any placed one it would overlap, with
  // a line back to its marker, so every name stays readable.
  struct Label {
    ImVec2 marker, at, size;
    const char* text;
  };
  std::vector<Label> labels;
  for (const Landmark& l : scene_->landmarks()) {
    const ProjectedPoint p = SceneRenderer::project(camera, l.position, w, h);
    if (!p.visible) continue;
    const ImVec2 marker(origin.x + p.x, origin.y + p.y);
    const ImVec2 size = ImGui::CalcTextSize(l.name.c_str());
    // Right of the marker, or left of it where the view's edge would cut the name.
    const float x = marker.x + 8 + size.x <= origin.x + w ? marker.x + 8 : marker.x - 8 - size.x;
    labels.push_back({marker, ImVec2(x, marker.y - 7), size, l.name.c_str()});
  }
  std::stable_sort(labels.begin(), labels.end(), [](const Label& a, const Label& b) { return a.at.y < b.at.y; });
  const auto overlap = [](const Label& a, const Label& b) {
    return a.at.x < b.at.x + b.size.x && b.at.x < a.at.x + a.size.x && a.at.y < b.at.y + b.size.y && b.at.y < a.at.y + a.size.y;
  };
  for (std::size_t i = 0; i < labels.size(); ++i) {
    for (bool moved = true; moved;) {
      moved = false;
      for (std::size_t j = 0; j < i; ++j) {
        if (!overlap(labels[i], labels[j])) continue;
        labels[i].at.y = labels[j].at.y + labels[j].size.y + 1.0f;
        moved = true;
      }
    }
    const Label& l = labels[i];
    if (l.at.y > l.marker.y) {
      const float edge = l.at.x > l.marker.x ? l.at.x : l.at.x + l.size.x;
      draw->AddLine(l.marker, ImVec2(edge, l.at.y + 0.5f * l.size.y), IM_COL32(255, 255, 255, 120));
    }
    draw->AddText(l.at, IM_COL32(255, 255, 255, 230), l.text);
  }
}

void ConsoleWindow::draw_outside_window(const ImVec2& pos, const ImVec2& size) {
  ImGui::SetNextWindowPos(pos);
  ImGui::SetNextWindowSize(size);
  ImGui::PushStyleVar(ImGuiStyleVar_WindowPadding, ImVec2(0, 0));
  ImGui::Begin("Outside view (drag to orbit, wheel to zoom)", nullptr,
               ImGuiWindowFlags_NoMove | ImGuiWindowFlags_NoResize | ImGuiWindowFlags_NoCollapse | ImGuiWindowFlags_NoScrollbar);
  const ImVec2 avail = ImGui::GetContentRegionAvail();
  const int w = std::max(16, static_cast<int>(avail.x)), h = std::max(16, static_cast<int>(avail.y));
  outside_target_.resize(scaled(w), scaled(h), 0);
  const CameraView camera = ui_.orbit.view(static_cast<float>(w) / static_cast<float>(h));
  scene_->draw_outside(outside_target_, camera);
  const ImVec2 origin = ImGui::GetCursorScreenPos();
  ImGui::Image(reinterpret_cast<ImTextureID>(static_cast<std::intptr_t>(outside_target_.texture())), ImVec2(float(w), float(h)),
               ImVec2(0, 1), ImVec2(1, 0));
  ui_.outside_rect = {origin.x, origin.y, float(w), float(h)};
  if (ImGui::IsItemHovered()) {
    const ImGuiIO& io = ImGui::GetIO();
    if (ImGui::IsMouseDragging(ImGuiMouseButton_Left)) ui_.orbit.drag(io.MouseDelta.x, io.MouseDelta.y);
    if (io.MouseWheel != 0.0f) ui_.orbit.zoom(io.MouseWheel);
  }
  draw_landmark_labels(ImGui::GetWindowDrawList(), origin, camera, float(w), float(h));
  ImGui::End();
  ImGui::PopStyleVar();
}

void ConsoleWindow::layout_and_draw() {
  const ImVec2 display = ImGui::GetIO().DisplaySize;
  const float left = std::floor(display.x * 0.62f);
  const float views = std::floor(display.y * 0.60f);
  draw_endoscope_window(ImVec2(0, 0), ImVec2(std::floor(left * 0.5f), views));
  draw_outside_window(ImVec2(std::floor(left * 0.5f), 0), ImVec2(left - std::floor(left * 0.5f), views));
  // A small window scrolls sideways rather than cutting off the panels' right-hand column.
  const ImGuiWindowFlags fixed =
      ImGuiWindowFlags_NoMove | ImGuiWindowFlags_NoResize | ImGuiWindowFlags_NoCollapse | ImGuiWindowFlags_HorizontalScrollbar;
  ImGui::SetNextWindowPos(ImVec2(0, views));
  ImGui::SetNextWindowSize(ImVec2(left, display.y - views));
  ImGui::Begin("Profiler", nullptr, fixed);
  draw_profiler_panel(controller_);
  ImGui::End();
  ImGui::SetNextWindowPos(ImVec2(left, 0));
  ImGui::SetNextWindowSize(ImVec2(display.x - left, display.y));
  ImGui::Begin("Resecto", nullptr, fixed);
  if (ImGui::CollapsingHeader("Simulation", ImGuiTreeNodeFlags_DefaultOpen)) draw_simulation_panel(controller_);
  if (ImGui::CollapsingHeader("Tissue parameters", ImGuiTreeNodeFlags_DefaultOpen)) draw_parameter_panel(controller_);
  if (ImGui::CollapsingHeader("Device", ImGuiTreeNodeFlags_DefaultOpen)) draw_device_panel(controller_);
  // While a recording is shown the core goes on live behind it: the metrics are the live core's.
  const char* metrics_title = ui_.show_replay && ui_.replay.is_open() ? "Procedure metrics: the live core, not the replay###metrics"
                                                                      : "Procedure metrics###metrics";
  if (ImGui::CollapsingHeader(metrics_title, ImGuiTreeNodeFlags_DefaultOpen)) draw_metrics_panel(controller_);
  if (ImGui::CollapsingHeader("Recording", ImGuiTreeNodeFlags_DefaultOpen)) draw_recording_panel(controller_);
  if (ImGui::CollapsingHeader("Replay", ImGuiTreeNodeFlags_DefaultOpen)) draw_replay_panel(controller_);
  ImGui::End();
}

Status ConsoleWindow::choose_shown(bool fresh_live_frame) {
  const LiveFrame& f = controller_.frame();
  if (ui_.show_replay && ui_.replay.is_open()) {
    if (!replay_renderer_ || replay_renderer_path_ != ui_.replay.path()) {
      Result<std::unique_ptr<SceneRenderer>> created = SceneRenderer::create(ui_.replay.prostate());
      if (!created) return Error{created.error()};
      replay_renderer_ = std::move(*created);
      replay_renderer_path_ = ui_.replay.path();
    }
    const SimulationSnapshot& replayed = ui_.replay.snapshot();
    replay_renderer_->update(replayed, ui_.replay.cutting_shown());
    shown_ = &replayed;
    scene_ = replay_renderer_.get();
    return Ok{};
  }
  if (fresh_live_frame || scene_ != &renderer_) renderer_.update(f.snapshot, (f.status.pedals & kPedalCut) != 0);
  shown_ = &f.snapshot;
  scene_ = &renderer_;
  return Ok{};
}

Status ConsoleWindow::run() {
  std::int64_t last_frame_ns = now_ns();
  // The hand-driven device and replay playback advance by the time between frame starts: a frame's
  // whole period, not just the wait between the last swap and this frame's start (audit 8, G17:
  // holding a key moved the sheath 0.1 mm in 3 s, and replay played 2 ms in 3 s).
  std::int64_t last_begin_ns = last_frame_ns;
  Status failure = Ok{};
  // Ctrl-C in the terminal closes the window as its close button does (console/live/interrupt.h).
  while (!quit_ && !glfwWindowShouldClose(window_) && interrupt_signal() == 0) {
    glfwPollEvents();
    const std::int64_t begin_ns = now_ns();
    const double dt_s = std::min(0.25, static_cast<double>(begin_ns - last_begin_ns) * 1e-9);
    last_begin_ns = begin_ns;
    while (next_action_ < actions_.size() && actions_[next_action_].frame <= ui_.frame) {
      if (Status applied = apply_action(actions_[next_action_++]); !applied) {
        failure = applied;
        quit_ = true;
      }
    }
    const bool fresh = controller_.refresh() || !have_frame_;
    have_frame_ = true;
    const LiveFrame& f = controller_.frame();
    if (fresh) controller_.track_changes();
    ui_.pacing.frame_begins(f.status.deadline_ticks, f.status.deadline_misses, begin_ns, slowed(ui_.frame));
    ui_.replay.advance(dt_s);
    if (Status chosen = choose_shown(fresh); !chosen) {
      failure = chosen;
      quit_ = true;
    }

    ImGui_ImplOpenGL3_NewFrame();
    ImGui_ImplGlfw_NewFrame();
    ImGui::NewFrame();
    read_manual_input(dt_s);
    if (!ImGui::GetIO().WantCaptureKeyboard) {
      // Shortcuts on keys the hand-driven device leaves free (ImGui 1.86 indexes keys by GLFW code).
      if (ImGui::IsKeyPressed(GLFW_KEY_P, false)) f.status.paused ? controller_.resume() : controller_.pause();
      if (ImGui::IsKeyPressed(GLFW_KEY_N, true)) controller_.step(1);
    }
    layout_and_draw();
    ImGui::Render();
    int fb_w = 0, fb_h = 0;
    glfwGetFramebufferSize(window_, &fb_w, &fb_h);
    glViewport(0, 0, fb_w, fb_h);
    glClearColor(0.06f, 0.06f, 0.07f, 1.0f);
    glClear(GL_COLOR_BUFFER_BIT);
    ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());

    if (options_.frames > 0 && ui_.frame + 1 == options_.frames && !options_.screenshot_path.empty()) {
      screenshots_due_.push_back(options_.screenshot_path);
    }
    for (const std::string& path : screenshots_due_) {
      if (Status saved = save_framebuffer_png(path, fb_w, fb_h); !saved) {
        failure = saved;
        quit_ = true;
      } else {
        ui_.screenshots.push_back(path);
      }
    }
    screenshots_due_.clear();
    if (slowed(ui_.frame)) std::this_thread::sleep_for(std::chrono::duration<double, std::milli>(options_.slow_frame_ms));
    glfwSwapBuffers(window_);

    const std::int64_t shown_ns = now_ns();
    // Input to photon: the device report behind the snapshot just shown, to the swap that shows it.
    if (fresh && f.status.newest_sample_host_ns > ui_.last_counted_sample_ns) {
      ui_.input_to_photon_us.add(static_cast<double>(shown_ns - f.status.newest_sample_host_ns) * 1e-3);
      ui_.last_counted_sample_ns = f.status.newest_sample_host_ns;
    }
    const double frame_ms = static_cast<double>(shown_ns - last_frame_ns) * 1e-6;
    if (ui_.frame > 0) ui_.frame_ms_as_us.add(frame_ms * 1e3);
    ui_.frame_history_ms[ui_.frame_history_next] = static_cast<float>(frame_ms);
    ui_.frame_history_next = static_cast<std::uint32_t>((ui_.frame_history_next + 1) % ui_.frame_history_ms.size());
    last_frame_ns = shown_ns;
    if (!frame_spans_.empty()) {
      const std::uint64_t drawn_tick = shown_ != nullptr ? shown_->tick : 0;
      frame_spans_[ui_.frame % frame_spans_.size()] = {begin_ns, shown_ns - begin_ns, ui_.frame, drawn_tick};
    }
    ++ui_.frame;
    if (options_.frames > 0 && ui_.frame >= options_.frames) quit_ = true;
  }
  if (failure && interrupt_signal() == 0) failure = account_for_unrun_actions();
  return failure;
}

Status ConsoleWindow::account_for_unrun_actions() const {
  // A script's actions past the session's end (after a quit, past --frames, or the window closed)
  // never ran; an output among them is a failed session, as a --screenshot never taken is (audit 8, G6).
  if (next_action_ >= actions_.size()) return Ok{};
  const std::size_t unrun = actions_.size() - next_action_;
  for (std::size_t i = next_action_; i < actions_.size(); ++i) {
    const Action& a = actions_[i];
    const bool output = a.verb == ActionVerb::kScreenshot || (a.verb == ActionVerb::kRecord && a.words[0] != "stop") ||
                        (a.verb == ActionVerb::kPreset && a.words[0] == "save");
    if (output) {
      return Error{options_.actions_path + ":" + std::to_string(a.line) + ": frame " + std::to_string(a.frame) + " never came: the session ended after " +
                   std::to_string(ui_.frame) + " frames (a quit action, --frames or the window closed first), so this output was not written; " +
                   std::to_string(unrun) + " of the script's actions did not run"};
    }
  }
  std::fprintf(stderr, "note: %zu of %s's actions did not run (from line %d, frame %llu): the session ended after %llu frames\n", unrun,
               options_.actions_path.c_str(), actions_[next_action_].line, static_cast<unsigned long long>(actions_[next_action_].frame),
               static_cast<unsigned long long>(ui_.frame));
  return Ok{};
}

ordered_json make_report(CoreSession& session, ConsoleUi& ui, const ConsoleOptions& options, double wall_s, int width, int height) {
  ordered_json r;
  r["frames"] = ui.frame;
  r["wall_s"] = wall_s;
  r["window"] = {width, height};
  r["views"] = {{"endoscope", ui.endoscope_rect}, {"outside", ui.outside_rect}};
  r["frame_ms"] = {{"median", ui.frame_ms_as_us.quantile(0.5) * 1e-3}, {"p99", ui.frame_ms_as_us.quantile(0.99) * 1e-3},
                   {"max", ui.frame_ms_as_us.max() * 1e-3}};
  const auto pacing = [](const FramePacing::Kind& k) {
    return ordered_json{{"frames", k.frames},
                        {"wall_s", k.wall_s},
                        {"deadline_ticks", k.ticks},
                        {"deadline_misses", k.misses},
                        {"miss_fraction", k.ticks ? static_cast<double>(k.misses) / static_cast<double>(k.ticks) : 0.0},
                        {"ticks_per_s", k.wall_s > 0.0 ? static_cast<double>(k.ticks) / k.wall_s : 0.0}};
  };
  r["frame_pacing"] = {{"slow_frame_ms", options.slow_frame_ms}, {"slow_frame_every", options.slow_frame_every},
                       {"slow_frames", pacing(ui.pacing.slow())}, {"other_frames", pacing(ui.pacing.normal())}};
  r["input_to_photon_ms"] = {{"median", ui.input_to_photon_us.quantile(0.5) * 1e-3}, {"p99", ui.input_to_photon_us.quantile(0.99) * 1e-3},
                             {"max", ui.input_to_photon_us.max() * 1e-3}, {"samples", ui.input_to_photon_us.count()}};
  const Simulation& sim = session.simulation();
  const DeadlineReport& d = session.deadlines();
  r["core"] = {{"ticks", sim.tick()},
               {"state_hash", hex_hash(sim.state_hash())},
               {"surface_triangles", sim.prostate().surface.triangle_count()},
               {"deadline_ticks", d.ticks},
               {"deadline_misses", d.misses},
               {"miss_fraction", d.ticks ? static_cast<double>(d.misses) / static_cast<double>(d.ticks) : 0.0},
               {"max_late_us", d.max_late_us},
               {"resynchronizations", d.resynchronizations},
               {"scheduling", session.realtime_priority_held() ? "SCHED_FIFO " + std::to_string(kCoreFifoPriority) : std::string("normal")}};
  if (session.core_cpu() >= 0) r["core"]["core_cpu"] = session.core_cpu();
  const std::string advice =
      realtime_advice(realtime_figures(sim, r["core"]["miss_fraction"].get<double>(), session.profiler().statistics(Stage::kTick).p99_us));
  if (!advice.empty()) r["core"]["advice"] = advice;
  ordered_json stages = ordered_json::object();
  for (int s = 0; s < kStageCount; ++s) {
    const StageStatistics st = session.profiler().statistics(static_cast<Stage>(s));
    stages[stage_name(static_cast<Stage>(s))] = {{"median_us", st.median_us}, {"p99_us", st.p99_us}, {"max_us", st.max_us},
                                                 {"budget_us", st.budget_us}, {"over_budget", st.over_budget}};
  }
  r["stages"] = stages;
  r["metrics"] = metrics_json(sim.metrics());
  ordered_json device = {{"transport", session.device_description()}};
  if (LiveDevice* live = session.live_device()) {
    const LinkCounters c = live->link().published_counters();
    device["reports"] = c.reports;
    device["lost"] = c.lost;
    device["rate_hz"] = c.rate_hz;
    device["latency_us"] = {{"median", c.latency_median_us}, {"p99", c.latency_p99_us}};
  }
  r["device"] = device;
  ordered_json changes = ordered_json::array();
  for (const ParameterChange& c : ui.changes) {
    changes.push_back({{"key", std::string(tissue_parameter_spec(c.parameter).key)},
                       {"value", c.value},
                       {"frame_sent", c.frame_sent},
                       {"stamped_tick", c.stamped_tick},
                       {"applied_tick", c.applied_tick},
                       {"first_frame_shown", c.first_frame_shown},
                       {"shown_snapshot_tick", c.shown_snapshot_tick},
                       {"shown_value", c.shown_value}});
  }
  r["parameter_changes"] = changes;
  r["screenshots"] = ui.screenshots;
  if (const int signal_number = interrupt_signal(); signal_number != 0) r["interrupted"] = signal_name(signal_number);
  const CoreStatus& status = session.frames().read_slot().status;
  r["recording"] = {{"active", status.recording}, {"path", std::string(status.recording_path.data())},
                    {"finished", status.recordings_finished}, {"bytes", status.recorded_bytes}, {"ticks", status.recorded_ticks},
                    {"keyframes", status.recorded_keyframes}, {"lost", status.recording_lost},
                    {"message", std::string(status.recording_message.data())}};
  if (status.recording || status.recordings_finished > 0) {
    // Only a recording from tick 0 can be re-simulated (scored, verified); said here and on the panel.
    r["recording"]["start_tick"] = status.recording_start_tick;
    r["recording"]["from_first_tick"] = status.recording_start_tick == 0;
  }
  if (ui.replay.is_open()) {
    ordered_json replay = {{"path", ui.replay.path()}, {"time_s", ui.replay.time_s()}, {"step_tick", ui.replay.step_tick_shown()}};
    if (ui.replay.keyframe_number_shown()) replay["keyframe"] = *ui.replay.keyframe_number_shown();
    const RigidPose& sheath = ui.replay.shown_tool().sheath;
    replay["sheath_tip_m"] = {sheath.translation.x, sheath.translation.y, sheath.translation.z};
    replay["loop_travel_mm"] = units::m_to_mm(ui.replay.loop_travel_shown_m());
    replay["cutting"] = ui.replay.cutting_shown();
    if (const ReplayVerification* v = ui.replay.verification()) {
      replay["verification"] = {{"error", v->error},
                                {"ticks", v->ticks},
                                {"verified", v->verified},
                                {"mismatches", v->mismatches},
                                {"unverified", v->unverified}};
    }
    r["replay"] = replay;
  }
  ordered_json hashes = ordered_json::array();
  for (const auto& [tick, hash] : session.collision_hashes()) hashes.push_back({tick, hex_hash(hash)});
  r["collision_hashes"] = hashes;
  return r;
}

}  // namespace

bool display_available() {
  const char* x = std::getenv("DISPLAY");
  const char* wayland = std::getenv("WAYLAND_DISPLAY");
  return (x && *x) || (wayland && *wayland);
}

Result<ordered_json> run_console(const ConsoleOptions& options) {
  std::vector<Action> actions;
  if (!options.actions_path.empty()) {
    Result<std::vector<Action>> loaded = load_actions(options.actions_path);
    if (!loaded) return Error{loaded.error()};
    actions = std::move(*loaded);
    const bool manual = options.core.device.source == DeviceSource::kEmulatorManual;
    if (Status fits = check_actions_for_device(actions, manual, options.actions_path); !fits) return Error{fits.error()};
  }
  glfwSetErrorCallback(on_glfw_error);
  if (!glfwInit()) {
    return Error{"cannot open the console's window (" + g_glfw_error + "); without a display use `resecto run --headless`"};
  }
  struct GlfwSession {
    ~GlfwSession() { glfwTerminate(); }
  } glfw_session;
  glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 3);
  glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 3);
  glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
  glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
  // A size not asked for fits the screen (audit 11: 1600 x 1000 on a 1024 x 700 screen); one asked for is kept.
  int width = options.settings.window_width, height = options.settings.window_height;
  int area_x = 0, area_y = 0, area_w = 0, area_h = 0;
  if (GLFWmonitor* monitor = glfwGetPrimaryMonitor()) glfwGetMonitorWorkarea(monitor, &area_x, &area_y, &area_w, &area_h);
  if (width == 0) width = area_w > 0 ? std::clamp(area_w, 640, ConsoleSettings::kDefaultWidth) : ConsoleSettings::kDefaultWidth;
  if (height == 0) height = area_h > 0 ? std::clamp(area_h, 480, ConsoleSettings::kDefaultHeight) : ConsoleSettings::kDefaultHeight;
  GLFWwindow* window = glfwCreateWindow(width, height, "Resecto operator console",
                                        nullptr, nullptr);
  if (!window) return Error{"cannot create an OpenGL 3.3 core window (" + g_glfw_error + ")"};
  glfwMakeContextCurrent(window);
  glfwSwapInterval(options.vsync ? 1 : 0);

  CoreSessionOptions core = options.core;
  core.simulation.parameters = options.settings.parameters;
  Result<std::unique_ptr<CoreSession>> created = [&] {
    // Nothing is written yet: a Ctrl-C during a large model's build ends the console at once.
    const EndAtOnceOnInterrupt nothing_written_yet;
    return CoreSession::create(core);
  }();
  if (!created) {
    glfwDestroyWindow(window);
    return Error{created.error()};
  }
  CoreSession& session = **created;
  Result<std::unique_ptr<SceneRenderer>> renderer = SceneRenderer::create(session.simulation().prostate());
  if (!renderer) {
    glfwDestroyWindow(window);
    return Error{renderer.error()};
  }

  IMGUI_CHECKVERSION();
  ImGui::CreateContext();
  ImGui::GetIO().IniFilename = nullptr;  // the layout is fixed; nothing to remember between sessions
  ImGui::StyleColorsDark();
  ImGui::GetStyle().WindowRounding = 0.0f;
  ImGui_ImplGlfw_InitForOpenGL(window, true);
  ImGui_ImplOpenGL3_Init("#version 330 core");

  ConsoleOptions resolved = options;
  const char* renderer_name = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
  const std::string gl_renderer = renderer_name ? renderer_name : "unknown";
  const bool software = gl_renderer.find("llvmpipe") != std::string::npos || gl_renderer.find("softpipe") != std::string::npos;
  if (resolved.view_scale <= 0.0) resolved.view_scale = software ? 0.5 : 1.0;

  const auto wall_start = std::chrono::steady_clock::now();
  Status ran = Ok{};
  ordered_json report;
  ordered_json traced;  // what --trace wrote
  Status trace_written = Ok{};  // a trace that could not be written fails the session after its report
  {
    // The window first: it queues --record's start, which the core then takes before its first tick
    // (started the other way round, a loaded machine let the core tick first, and the recording began
    // at tick 1, which a replay refuses).
    ConsoleWindow console(window, resolved, session, **renderer, std::move(actions));
    session.start();
    ran = console.open_initial_replay();
    if (ran) ran = console.run();
    const std::vector<std::string>& taken = console.ui().screenshots;
    if (ran && !options.screenshot_path.empty() && std::find(taken.begin(), taken.end(), options.screenshot_path) == taken.end()) {
      ran = Error{options.screenshot_path + ": not written: the session ended after " + std::to_string(console.ui().frame) +
                  " frames, before the last of --frames " + std::to_string(options.frames) + " (a quit action or the window closed)"};
    }
    session.stop();
    session.frames().update();  // the core's last frame: the recording's final figures
    if (ran && !options.trace_path.empty()) {
      // The core has stopped: its profiler is this thread's to read.
      const std::vector<TraceSpan> frames = console.traced_frames();
      const std::array<TraceTrack, 1> tracks{TraceTrack{"console (frames: drawing to the swap)", "frame", "frame", frames}};
      trace_written = session.profiler().write_chrome_trace(options.trace_path, tracks);
      // A long session's trace holds its end: the report says from which tick.
      if (trace_written) traced = {{"path", options.trace_path}, {"first_tick", session.profiler().trace_first_tick()},
                         {"dropped_stage_timings", session.profiler().trace_dropped()}, {"frames", frames.size()}};
    }
    console.ui().replay.wait_for_verification();
    int w = 0, h = 0;
    glfwGetFramebufferSize(window, &w, &h);
    report = make_report(session, console.ui(), options, std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count(), w, h);
    report["renderer"] = {{"gl_renderer", gl_renderer}, {"view_scale", resolved.view_scale}};
    if (!traced.is_null()) report["trace"] = traced;
    renderer->reset();  // its GL objects go while the context lives
  }
  ImGui_ImplOpenGL3_Shutdown();
  ImGui_ImplGlfw_Shutdown();
  ImGui::DestroyContext();
  glfwDestroyWindow(window);
  if (!ran) return Error{ran.error()};
  if (!options.report_path.empty()) {
    if (Status written = write_file_atomically(options.report_path, report.dump(2) + "\n"); !written) return Error{written.error()};
  }
  if (!trace_written) return Error{trace_written.error()};
  // After the report (which holds it too): a recording lost is a failed session, as in a headless run.
  if (!session.recording_error().empty()) return Error{session.recording_error()};
  return report;
}

std::string summarize_console_report(const ordered_json& r) {
  char text[1024];
  const auto& core = r.at("core");
  std::snprintf(text, sizeof text,
                "console: %llu frames in %.1f s; frame median %.1f ms, p99 %.1f ms\n"
                "  input-to-photon  median %.1f ms, p99 %.1f ms (%llu frames)\n"
                "  core             %llu ticks, %llu of %llu deadlines missed (%.3f%%), worst %.0f us late; state hash %s\n",
                static_cast<unsigned long long>(r.at("frames").get<std::uint64_t>()), r.at("wall_s").get<double>(),
                r.at("frame_ms").at("median").get<double>(), r.at("frame_ms").at("p99").get<double>(),
                r.at("input_to_photon_ms").at("median").get<double>(), r.at("input_to_photon_ms").at("p99").get<double>(),
                static_cast<unsigned long long>(r.at("input_to_photon_ms").at("samples").get<std::uint64_t>()),
                static_cast<unsigned long long>(core.at("ticks").get<std::uint64_t>()),
                static_cast<unsigned long long>(core.at("deadline_misses").get<std::uint64_t>()),
                static_cast<unsigned long long>(core.at("deadline_ticks").get<std::uint64_t>()), 100.0 * core.at("miss_fraction").get<double>(),
                core.at("max_late_us").get<double>(), core.at("state_hash").get<std::string>().c_str());
  std::string summary = text;
  if (core.contains("advice")) summary += "  advice           " + core.at("advice").get<std::string>() + "\n";
  const auto& recording = r.at("recording");
  if (recording.contains("from_first_tick") && !recording.at("from_first_tick").get<bool>()) {
    summary += "  recording        " + recording.at("path").get<std::string>() + " " +
               mid_session_recording_note(recording.at("start_tick").get<std::uint64_t>()) + "\n";
  }
  return summary;
}

}  // namespace resecto::gui
